"""Development harness (not a scoring run): one video through blob detection and the offline closed set with and
without the learned look, scored on points. Usage: dev.py VIDEO GT_KIND N [radius]"""
import sys
import time
from pathlib import Path

import numpy as np

from lookalike.bench.datasets import read_hexbug_points
from lookalike.eval import evaluate_points
from lookalike.io.video_frames import source_frames
from lookalike.pipeline.blob_detections import auto_blob_config, cached_blob_detections
from lookalike.trackers.offline.closed_set import track_closed_set
from lookalike.vision.blob_auto import BOX_TRACKER_PARAMS


def score(rows, gt, radius, n_frames):
    frame, ids, xy = gt
    c = rows[:, 2:4] + rows[:, 4:6] / 2
    return evaluate_points(frame, ids, xy, rows[:, 0].astype(int), rows[:, 1].astype(int), c, radius=radius,
                           num_frames=n_frames)


def main():
    video, kind, n = Path(sys.argv[1]), sys.argv[2], int(sys.argv[3])
    radius = float(sys.argv[4]) if len(sys.argv) > 4 else 15.0
    config, _ = auto_blob_config(video, [], n)
    found = cached_blob_detections(video, config)
    frames, _, fps = source_frames(video)
    img = next(iter(frames))
    if kind == "hexbug":
        gt = read_hexbug_points(video.with_suffix(".csv"), (img.shape[1], img.shape[0]))
    else:
        gt_rows = np.loadtxt(video.parent / "gt.txt", delimiter=",")
        gt = gt_rows[:, 0].astype(int), gt_rows[:, 1].astype(int), gt_rows[:, 2:4] + gt_rows[:, 4:6] / 2
    for use in (False, True):
        t0 = time.perf_counter()
        rows = track_closed_set(found.rows, n, fps or 25.0, n_frames=found.frames, online=dict(BOX_TRACKER_PARAMS),
                                shapes=found.shapes if use else None)
        m = score(rows, gt, radius, found.frames)
        print(f"{video.stem} shapes={use}: IDF1 {m['IDF1']:.2f} IDSW {m['IDSW']:.0f} MOTA {m['MOTA']:.2f} "
              f"({time.perf_counter() - t0:.1f} s)")


main()
