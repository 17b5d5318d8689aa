"""Blob detector (+ a tracker) on the HexBug clips, scored against the CSV head points.

Detection recall/precision: a ground-truth head point is found when a detection box, grown by
``--margin`` pixels, contains it (one-to-one, Hungarian on the point-to-box distance). Tracking:
the tracker runs on the blob boxes and its box centres are scored with point matching within
``--radius`` pixels (IDF1, MOTA via ``lookalike.eval.evaluate_points``; a box centre lies about
half a bug from the head, hence the large default radius). Some CSVs have x and y swapped
(listed in ../shared/data/README.md); they are swapped back here.

    .venv/bin/python benchmarks/hexbug_blobs.py [--clips training010 ...] [--tracker sort]
"""

from __future__ import annotations

import argparse
import csv
import sys
import time
from pathlib import Path

import numpy as np

from lookalike.association import assign
from lookalike.eval import evaluate_points
from lookalike.trackers import make_tracker
from lookalike.types import Frame
from lookalike.vision.blob import BlobConfig, BlobDetector, read_video

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _common import SHARED_DATA  # noqa: E402

SWAPPED_XY = {"training020", "training058", "training076", "training078", "training079", "training082",
              "training083", "training089"}


def read_points(path: Path) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(frame0 (n,), id (n,), xy (n, 2))`` from a HexBug CSV (``,t,hexbug,x,y``), x/y fixed for swapped clips."""
    rows = []
    with open(path, newline="") as fh:
        for rec in csv.DictReader(fh):
            rows.append((int(float(rec["t"])), int(float(rec["hexbug"])), float(rec["x"]), float(rec["y"])))
    arr = np.array(rows, dtype=float).reshape(-1, 4)
    xy = arr[:, 2:4]
    if path.stem in SWAPPED_XY:
        xy = xy[:, ::-1]
    return arr[:, 0].astype(int), arr[:, 1].astype(int), np.ascontiguousarray(xy)


def point_box_distance(xy: np.ndarray, xywh: np.ndarray) -> np.ndarray:
    """``(n, m)`` distance in pixels from points ``(n, 2)`` to boxes ``(m, 4)`` (0 inside)."""
    x0, y0 = xywh[:, 0], xywh[:, 1]
    x1, y1 = x0 + xywh[:, 2], y0 + xywh[:, 3]
    dx = np.maximum(np.maximum(x0[None] - xy[:, :1], 0), xy[:, :1] - x1[None])
    dy = np.maximum(np.maximum(y0[None] - xy[:, 1:], 0), xy[:, 1:] - y1[None])
    return np.hypot(dx, dy)


def run_clip(video: Path, csv_path: Path, tracker_name: str, margin: float, radius: float, cfg: BlobConfig) -> dict:
    frames = read_video(str(video))
    gt_t, gt_id, gt_xy = read_points(csv_path)
    detector = BlobDetector(cfg).fit(frames)
    tracker = make_tracker(tracker_name)
    found = total = tp_boxes = n_boxes = 0
    res_f, res_id, res_xy = [], [], []
    t0 = time.perf_counter()
    for k, image in enumerate(frames):
        dets = detector(image)
        here = gt_t == k
        pts = gt_xy[here]
        total += len(pts)
        n_boxes += len(dets)
        if len(pts) and len(dets):
            cost = point_box_distance(pts, dets.xywh)
            matches = assign(cost, max_cost=margin).matches
            found += len(matches)
            tp_boxes += len(matches)
        for trk in tracker.update(Frame(index=k, time=k / 10.0, detections=dets)):
            if trk.xywh is None:
                continue
            x, y, w, h = trk.xywh
            res_f.append(k + 1)
            res_id.append(trk.track_id)
            res_xy.append((x + w / 2, y + h / 2))
    seconds = time.perf_counter() - t0
    scores = evaluate_points(
        gt_t + 1, gt_id, gt_xy, np.array(res_f, dtype=int), np.array(res_id, dtype=int),
        np.array(res_xy, dtype=float).reshape(-1, 2), radius=radius, metrics=("CLEAR", "Identity"),
        num_frames=len(frames),
    )
    return {
        "clip": video.stem,
        "frames": len(frames),
        "gt_points": total,
        "recall": found / total if total else float("nan"),
        "precision": tp_boxes / n_boxes if n_boxes else float("nan"),
        "IDF1": scores["IDF1"],
        "MOTA": scores["MOTA"],
        "fps": len(frames) / seconds,
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--clips", nargs="*", help="clip names (default: every clip with a video)")
    parser.add_argument("--tracker", default="sort")
    parser.add_argument("--margin", type=float, default=20.0, help="px a head point may lie outside its box")
    parser.add_argument("--radius", type=float, default=120.0, help="px for point matching of track centres")
    parser.add_argument("--threshold", type=float, default=30.0)
    parser.add_argument("--min-area", type=float, default=800.0)
    args = parser.parse_args()
    root = SHARED_DATA / "hexbug"
    if not root.is_dir():
        sys.exit(f"HexBug data not found at {root}")
    videos = sorted(root.glob("*.mp4"))
    if args.clips:
        videos = [v for v in videos if v.stem in set(args.clips)]
    cfg = BlobConfig(threshold=args.threshold, min_area_px=args.min_area, open_px=9, stabilise=True)
    rows = []
    print(f"{'clip':<14}{'frames':>7}{'points':>8}{'recall':>8}{'prec':>8}{'IDF1':>8}{'MOTA':>8}{'fps':>7}")
    for video in videos:
        r = run_clip(video, video.with_suffix(".csv"), args.tracker, args.margin, args.radius, cfg)
        rows.append(r)
        print(f"{r['clip']:<14}{r['frames']:>7}{r['gt_points']:>8}{r['recall']:>8.3f}{r['precision']:>8.3f}"
              f"{r['IDF1']:>8.3f}{r['MOTA']:>8.3f}{r['fps']:>7.1f}", flush=True)
    pts = sum(r["gt_points"] for r in rows)
    if pts:
        recall = sum(r["recall"] * r["gt_points"] for r in rows) / pts
        print(f"{'all':<14}{'':>7}{pts:>8}{recall:>8.3f}   (IDF1 mean {np.mean([r['IDF1'] for r in rows]):.3f})")


if __name__ == "__main__":
    main()
