"""Round 5 diagnosis (development arenas only): with variant A, what each wrong reference point's mapped row is --
a detection (measured), an identity placed in a merged blob, or another interpolated row -- and how far it is."""
import sys

import dev5
import numpy as np
from scipy.optimize import linear_sum_assignment

from lookalike.io.arena_files import write_arena
from lookalike.io.video_frames import source_frames
from lookalike.trackers.offline import closed_set
from lookalike.vision.blob_auto import BOX_TRACKER_PARAMS

captured = {}


def diagnose(seed):
    files = write_arena(dev5.work / f"arena{seed}", seed=seed)
    truth = np.loadtxt(files.gt, delimiter=",", ndmin=2)
    n = len(np.unique(truth[:, 1]))
    dev5.N[0] = n
    found, parts = dev5.detections_with_parts(files.video)
    inner = dev5.placer(parts, "A")

    def spy(rows, measured, merged):
        captured["measured"] = {(int(f), int(i)) for f, i in rows[measured, :2]}
        captured["merged"] = merged
        out = inner(rows, measured, merged)
        captured["moved"] = {(int(f), int(i)) for f, i in out[np.any(out[:, 2:4] != rows[:, 2:4], axis=1), :2]}
        return out

    closed_set.place_in_merges = spy
    fps = source_frames(files.video)[2] or 25.0
    rows = closed_set.track_closed_set(found.rows, n, fps, n_frames=found.frames, online=dict(BOX_TRACKER_PARAMS),
                                       shapes=found.shapes)
    ref = np.column_stack([truth[:, :2], truth[:, 2:4] + truth[:, 4:6] / 2])
    c = rows[:, 2:4] + rows[:, 4:6] / 2
    res_ids, res_idx = np.unique(rows[:, 1].astype(int), return_inverse=True)
    ref_ids, ref_idx = np.unique(ref[:, 1].astype(int), return_inverse=True)
    near = np.zeros((len(res_ids), len(ref_ids)))
    by = {f: np.flatnonzero(rows[:, 0] == f) for f in np.unique(rows[:, 0]).astype(int)}
    for g in range(len(ref)):
        r = by.get(int(ref[g, 0]), np.zeros(0, int))
        for k in r[np.hypot(*(c[r] - ref[g, 2:4]).T) <= 15]:
            near[res_idx[k], ref_idx[g]] += 1
    a, b = linear_sum_assignment(-near)
    mapped = {int(j): int(res_ids[i]) for i, j in zip(a, b)}
    merged_frames = {}
    for m in captured["merged"]:
        merged_frames.setdefault(int(m[0]), []).append(m[2:6])
    counts = {}
    for g in range(len(ref)):
        f, hid = int(ref[g, 0]), mapped.get(int(ref_idx[g]))
        r = by.get(f, np.zeros(0, int))
        mine = r[rows[r, 1] == hid] if hid is not None else r[:0]
        if len(mine) and np.hypot(*(c[mine[0]] - ref[g, 2:4])) <= 15:
            continue
        in_blob = any(x <= ref[g, 2] <= x + w and y <= ref[g, 3] <= y + h for x, y, w, h in merged_frames.get(f, []))
        if not len(mine):
            kind = "absent"
        elif (f, hid) in captured["moved"]:
            kind = "placed-in-merge"
        elif (f, hid) in captured["measured"]:
            kind = "measured"
        else:
            kind = "interpolated"
        other = bool(len(r)) and np.any(np.hypot(*(c[r] - ref[g, 2:4]).T) <= 15)
        key = (kind, "gt-in-merged-box" if in_blob else "gt-outside", "other-id-near" if other else "none-near")
        counts[key] = counts.get(key, 0) + 1
    return counts


total = {}
for s in [int(a) for a in sys.argv[1:]] or range(10):
    cnt = diagnose(s)
    for k, v in cnt.items():
        total[k] = total.get(k, 0) + v
    print(s, sum(cnt.values()), flush=True)
for k, v in sorted(total.items(), key=lambda kv: -kv[1]):
    print(v, *k)
