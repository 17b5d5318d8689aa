"""Blob detector + trackers on the HexBug clips, scored per clip against the CSV head points.

Detections come from ``lookalike bench real``'s loader (:func:`lookalike.bench.datasets.detect_hexbug`:
the blob settings ``lookalike track --detector blob`` estimates from each clip, cached on disk; head
points oriented by the frame bounds). Detection recall/precision: a
ground-truth head point is found when a detection box, grown by ``--margin`` pixels, contains it
(one-to-one, Hungarian on the point-to-box distance). Tracking: each tracker runs as in ``lookalike
bench real`` (:func:`~lookalike.bench.runner.track_rows`: boxtrack's defaults; its HexBug parameters chosen on
the clips' first halves only in the separate "tuned on this data" row) and its box centres are scored with point
matching within 120 px
(:func:`~lookalike.bench.runner.score_rows`: IDF1, MOTA; a box centre lies about half a bug from
the head, hence the large radius). ``boxtrack8``-style closed sets: ``--closed`` adds boxtrack with
``max_targets`` = the number of bugs annotated in the clip's CSV (the known team size).

    .venv/bin/python benchmarks/hexbug_blobs.py [--clips training010 ...] [--trackers boxtrack sort]
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

from lookalike.association import assign
from lookalike.bench.datasets import RealSequence, detect_hexbug, hexbug_clips
from lookalike.bench.runner import Entry, score_rows, track_rows
from lookalike.vision.blob_auto import BOX_TRACKER_PARAMS, infer_target_count

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _common import SHARED_DATA  # noqa: E402


def point_box_distance(xy: np.ndarray, xywh: np.ndarray) -> np.ndarray:
    """``(n, m)`` distance in pixels from points ``(n, 2)`` to boxes ``(m, 4)`` (0 inside)."""
    x0, y0 = xywh[:, 0], xywh[:, 1]
    x1, y1 = x0 + xywh[:, 2], y0 + xywh[:, 3]
    dx = np.maximum(np.maximum(x0[None] - xy[:, :1], 0), xy[:, :1] - x1[None])
    dy = np.maximum(np.maximum(y0[None] - xy[:, 1:], 0), xy[:, 1:] - y1[None])
    return np.hypot(dx, dy)


def detection_counts(seq: RealSequence, margin: float) -> tuple[int, int, int]:
    """``(head points found, head points, boxes)`` over the clip (one box explains at most one point)."""
    frame, _, xy = seq.gt_points
    found = points = boxes = 0
    for k in range(seq.length):
        pts, det = xy[frame == k + 1], seq.det_xywh[k]
        points, boxes = points + len(pts), boxes + len(det)
        if len(pts) and len(det):
            found += len(assign(point_box_distance(pts, det), max_cost=margin).matches)
    return found, points, boxes


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--clips", nargs="*", help="clip names (default: every clip with a video and a CSV)")
    parser.add_argument("--trackers", nargs="*", default=["boxtrack", "sort"])
    parser.add_argument("--margin", type=float, default=20.0, help="px a head point may lie outside its box")
    parser.add_argument("--closed", action="store_true", help="also boxtrack with max_targets = bugs in the CSV")
    args = parser.parse_args()
    root = SHARED_DATA / "hexbug"
    if not root.is_dir():
        sys.exit(f"HexBug data not found at {root}")
    videos = [v for v in hexbug_clips(root) if not args.clips or v.stem in set(args.clips)]
    head = f"{'clip':<13}{'frames':>7}{'points':>7}{'recall':>8}{'prec':>7}{'det fps':>8}"
    blob = ["boxtrack-blob"] if "boxtrack" in args.trackers else []
    labels = args.trackers + blob + (["closed"] if args.closed else [])
    head += "".join(f"{t + ' IDF1':>20}{'MOTA':>7}" for t in labels)
    print(head)
    totals = np.zeros(3)
    idf1: dict[str, list[float]] = {t: [] for t in labels}
    for video in videos:
        t0 = time.perf_counter()
        seq = detect_hexbug(video)
        fps = seq.length / (time.perf_counter() - t0)
        found, points, boxes = detection_counts(seq, args.margin)
        totals += (found, points, boxes)
        line = (f"{seq.name:<13}{seq.length:>7}{points:>7}{found / max(points, 1):>8.3f}"
                f"{found / max(boxes, 1):>7.3f}{fps:>8.1f}")
        entries = [Entry(t, t) for t in args.trackers]
        if blob:
            count = infer_target_count(np.array([len(d) for d in seq.det_xywh]))
            entries.append(Entry(blob[0], "boxtrack", params={**BOX_TRACKER_PARAMS,
                                                               **({"max_targets": count.n} if count.closed else {})}))
        if args.closed:
            entries.append(Entry("closed", "boxtrack", params={"max_targets": len(np.unique(seq.gt_points[1]))}))
        for e in entries:
            scores = score_rows(seq, track_rows(e, seq))
            idf1[e.label].append(scores["IDF1"])
            line += f"{scores['IDF1']:>20.3f}{scores['MOTA']:>7.3f}"
        print(line, flush=True)
    if len(videos):
        line = f"{'all':<13}{'':>7}{int(totals[1]):>7}{totals[0] / max(totals[1], 1):>8.3f}"
        line += f"{totals[0] / max(totals[2], 1):>7.3f}{'':>8}"
        line += "".join(f"{np.mean(idf1[t]):>20.3f}{'':>7}" for t in labels)
        print(line + "   (recall/precision pooled over points, IDF1 the mean over clips)")


if __name__ == "__main__":
    main()
