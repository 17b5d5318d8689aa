"""Diagnosis (development arenas, not a scoring run): the default's swapped and misplaced reference points of
errors5.py, split by whether the animal's centre lies in a detected box that holds another animal's centre too
(a merged blob) or in a box of its own, and the lengths of the runs of consecutive wrong frames per animal.
Arguments: seeds."""
import sys
import tempfile
from collections import Counter
from pathlib import Path

import numpy as np
from scipy.optimize import linear_sum_assignment

from lookalike.io.arena_files import write_arena
from lookalike.io.video_frames import source_frames
from lookalike.pipeline.blob_detections import auto_blob_config, cached_blob_detections
from lookalike.trackers.offline.closed_set import track_closed_set
from lookalike.vision.blob_auto import BOX_TRACKER_PARAMS

R = 15.0
work = Path(tempfile.mkdtemp(prefix="errors16-"))
kinds: Counter = Counter()
runs: Counter = Counter()
for seed in [int(s) for s in sys.argv[1:]] or range(10):
    files = write_arena(work / f"arena{seed}", seed=seed)
    truth = np.loadtxt(files.gt, delimiter=",", ndmin=2)
    ref = np.column_stack([truth[:, :2], truth[:, 2:4] + truth[:, 4:6] / 2])
    n = len(np.unique(truth[:, 1]))
    found = cached_blob_detections(files.video, auto_blob_config(files.video, [], n)[0])
    fps = source_frames(files.video)[2] or 25.0
    res = track_closed_set(found.rows, n, fps, n_frames=found.frames, online=dict(BOX_TRACKER_PARAMS),
                           shapes=found.shapes, parts=found.parts)
    c = res[:, 2:4] + res[:, 4:6] / 2
    rid, ridx = np.unique(res[:, 1].astype(int), return_inverse=True)
    gid, gidx = np.unique(ref[:, 1].astype(int), return_inverse=True)
    near = np.zeros((len(rid), len(gid)))
    for g in range(len(ref)):
        rows = np.flatnonzero(res[:, 0] == ref[g, 0])
        for r in rows[np.hypot(*(c[rows] - ref[g, 2:4]).T) <= R]:
            near[ridx[r], gidx[g]] += 1
    a, b = linear_sum_assignment(-near)
    mapped = {int(j): int(i) for i, j in zip(a, b)}
    wrong_frames: dict[int, list[int]] = {}
    for g in range(len(ref)):
        f = ref[g, 0]
        rows = np.flatnonzero(res[:, 0] == f)
        mine = rows[ridx[rows] == mapped.get(int(gidx[g]), -1)]
        if len(mine) and np.hypot(*(c[mine[0]] - ref[g, 2:4])) <= R:
            continue
        others = ref[(ref[:, 0] == f) & (np.arange(len(ref)) != g), 2:4]
        boxes = found.rows[found.rows[:, 0] == f, 2:6]
        inbox = [(b[0] <= p[0] <= b[0] + b[2]) & (b[1] <= p[1] <= b[1] + b[3]) for b in boxes for p in [ref[g, 2:4]]]
        merged = any(ok and np.any((others[:, 0] >= b[0]) & (others[:, 0] <= b[0] + b[2]) & (others[:, 1] >= b[1])
                                   & (others[:, 1] <= b[1] + b[3])) for ok, b in zip(inbox, boxes))
        swapped = bool(len(rows)) and np.any(np.hypot(*(c[rows] - ref[g, 2:4]).T) <= R)
        where = "merged" if merged else ("own box" if any(inbox) else "no box")
        kinds[(where, "swapped" if swapped else ("misplaced" if len(mine) else "missing"))] += 1
        wrong_frames.setdefault(int(ref[g, 1]), []).append(int(f))
    for frames in wrong_frames.values():
        breaks = np.flatnonzero(np.diff(frames) > 1)
        lengths = np.diff(np.concatenate([[0], breaks + 1, [len(frames)]]))
        for length in lengths:
            runs["1" if length == 1 else "2-5" if length <= 5 else "6-20" if length <= 20 else ">20"] += 1
            runs["points in runs " + ("1" if length == 1 else "2-5" if length <= 5 else "6-20" if length <= 20
                                      else ">20")] += int(length)
    print(seed, dict(kinds), flush=True)
print("kinds", dict(kinds))
print("runs", dict(runs))
