"""Diagnosis (not a scoring run; seeds already spent or development): which animal pairs the default keeps swapped for
20 frames or more, and how close their drawn traits are (scale, head darkness, band place; each over a rough spread).
Arguments: seeds. Output of 2026-12-07 for 10008 9014 4012 4002 in twins.txt."""
import sys
import tempfile
from pathlib import Path

import numpy as np
from scipy.optimize import linear_sum_assignment

from lookalike.io.arena_files import write_arena
from lookalike.io.video_frames import source_frames
from lookalike.pipeline.blob_detections import auto_blob_config, cached_blob_detections
from lookalike.sim.arena_render import simulate_arena
from lookalike.trackers.offline.closed_set import track_closed_set
from lookalike.vision.blob_auto import BOX_TRACKER_PARAMS

R = 15.0
work = Path(tempfile.mkdtemp(prefix="twins-"))
for seed in [int(s) for s in sys.argv[1:]]:
    files = write_arena(work / f"arena{seed}", seed=seed)
    tr = simulate_arena(None, seed).traits
    truth = np.loadtxt(files.gt, delimiter=",", ndmin=2)
    ref = np.column_stack([truth[:, :2], truth[:, 2:4] + truth[:, 4:6] / 2])
    n = len(np.unique(truth[:, 1]))
    found = cached_blob_detections(files.video, auto_blob_config(files.video, [], n)[0])
    fps = source_frames(files.video)[2] or 25.0
    res = track_closed_set(found.rows, n, fps, n_frames=found.frames, online=dict(BOX_TRACKER_PARAMS),
                           shapes=found.shapes, parts=found.parts)
    c = res[:, 2:4] + res[:, 4:6] / 2
    rid = np.unique(res[:, 1].astype(int))
    gid = np.unique(ref[:, 1].astype(int))
    near = np.zeros((len(rid), len(gid)))
    # per (frame, gt) which result id is within R (nearest)
    who = {}
    for g in range(len(ref)):
        rows = np.flatnonzero(res[:, 0] == ref[g, 0])
        d = np.hypot(*(c[rows] - ref[g, 2:4]).T)
        ok = rows[d <= R]
        for r in ok:
            near[np.searchsorted(rid, int(res[r, 1])), np.searchsorted(gid, int(ref[g, 1]))] += 1
        if len(ok):
            who[(int(ref[g, 0]), int(ref[g, 1]))] = int(res[rows[np.argmin(d)], 1])
    a, b = linear_sum_assignment(-near)
    mapped = {int(gid[j]): int(rid[i]) for i, j in zip(a, b)}
    inv = {v: k for k, v in mapped.items()}
    # long runs where gt animal g is held by the id mapped to another animal h
    held = {}
    for (f, g), r in who.items():
        if r != mapped[g] and r in inv:
            held.setdefault((g, inv[r]), []).append(f)
    traits = np.column_stack([tr.scale / 0.1, tr.head / 0.12, tr.band_at / 0.4])  # crude units of spread
    dist = np.linalg.norm(traits[:, None] - traits[None], axis=2)
    order = np.argsort(dist[np.triu_indices(n, 1)])
    iu = np.triu_indices(n, 1)
    rank = {(int(iu[0][k]) + 1, int(iu[1][k]) + 1): r for r, k in enumerate(order)}
    print(f"seed {seed}")
    for (g, h), fs in sorted(held.items(), key=lambda kv: -len(kv[1])):
        if len(fs) < 20:
            continue
        p = tuple(sorted((g, h)))
        print(f"  animal {g} held by {h}'s id in {len(fs)} frames ({min(fs)}-{max(fs)}); trait distance "
              f"{dist[g-1, h-1]:.2f} (rank {rank[p]} of {len(order)} pairs); "
              f"scale {tr.scale[g-1]:.3f}/{tr.scale[h-1]:.3f} "
              f"head {tr.head[g-1]:.3f}/{tr.head[h-1]:.3f} band {tr.band_at[g-1]:.2f}/{tr.band_at[h-1]:.2f}")
