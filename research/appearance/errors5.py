"""Where the default's identity errors are on the development arenas (seeds 0-9): each reference point, under the
global id mapping of IDF1, is right (mapped id within 15 px), swapped (another id within 15 px), misplaced (no id
within 15 px, the mapped one present) or missing; split by whether the animal touches another (its reference
centre within CONTACT body lengths of another's). Not a scoring run. Runs the command's default closed set (with
the detector's parts since round 5; the round-5 diagnosis in rule5.md ran before parts existed). Arguments: seeds."""
import sys
import tempfile
from pathlib import Path

import numpy as np
from scipy.optimize import linear_sum_assignment

from lookalike.io.arena_files import write_arena
from lookalike.io.video_frames import source_frames
from lookalike.pipeline.blob_detections import auto_blob_config, cached_blob_detections
from lookalike.trackers.offline.closed_set import track_closed_set
from lookalike.vision.blob_auto import BOX_TRACKER_PARAMS

R = 15.0
work = Path(tempfile.mkdtemp(prefix="errors5-"))


def classify(result, truth):
    """Counts per (contact, kind)."""
    ref = np.column_stack([truth[:, :2], truth[:, 2:4] + truth[:, 4:6] / 2])
    body = float(np.median(np.maximum(truth[:, 4], truth[:, 5])))
    c = result[:, 2:4] + result[:, 4:6] / 2
    res_ids, res_idx = np.unique(result[:, 1].astype(int), return_inverse=True)
    ref_ids, ref_idx = np.unique(ref[:, 1].astype(int), return_inverse=True)
    near = np.zeros((len(res_ids), len(ref_ids)))
    rows_of = {f: np.flatnonzero(result[:, 0] == f) for f in np.unique(result[:, 0]).astype(int)}
    refs_of = {f: np.flatnonzero(ref[:, 0] == f) for f in np.unique(ref[:, 0]).astype(int)}
    for g in range(len(ref)):
        rows = rows_of.get(int(ref[g, 0]), np.zeros(0, int))
        d = np.hypot(*(c[rows] - ref[g, 2:4]).T)
        for r in rows[d <= R]:
            near[res_idx[r], ref_idx[g]] += 1
    a, b = linear_sum_assignment(-near)
    mapped = {int(j): int(i) for i, j in zip(a, b)}
    out = {}
    for g in range(len(ref)):
        f = int(ref[g, 0])
        others = refs_of[f][refs_of[f] != g]
        contact = bool(len(others)) and np.min(np.hypot(*(ref[others, 2:4] - ref[g, 2:4]).T)) <= 1.0 * body
        rows = rows_of.get(f, np.zeros(0, int))
        d = np.hypot(*(c[rows] - ref[g, 2:4]).T)
        mine = rows[res_idx[rows] == mapped.get(int(ref_idx[g]), -1)]
        if len(mine) and np.hypot(*(c[mine[0]] - ref[g, 2:4])) <= R:
            kind = "right"
        elif np.any(d <= R):
            kind = "swapped"
        elif len(mine):
            kind = "misplaced"
        else:
            kind = "missing"
        out[(contact, kind)] = out.get((contact, kind), 0) + 1
    return out


total = {}
for seed in (range(10) if len(sys.argv) < 2 else [int(s) for s in sys.argv[1:]]):
    files = write_arena(work / f"arena{seed}", seed=seed)
    truth = np.loadtxt(files.gt, delimiter=",", ndmin=2)
    n = len(np.unique(truth[:, 1]))
    config, _ = auto_blob_config(files.video, [], n)
    found = cached_blob_detections(files.video, config)
    fps = source_frames(files.video)[2] or 25.0
    rows = track_closed_set(found.rows, n, fps, n_frames=found.frames, online=dict(BOX_TRACKER_PARAMS),
                            shapes=found.shapes, parts=found.parts)
    counts = classify(rows, truth)
    for k, v in counts.items():
        total[k] = total.get(k, 0) + v
    print(seed, {f"{'touch' if k[0] else 'alone'}/{k[1]}": v for k, v in sorted(counts.items())}, flush=True)
print("all", {f"{'touch' if k[0] else 'alone'}/{k[1]}": v for k, v in sorted(total.items())})
