"""Tracker speed on the MOT15 detections: lookalike SORT beside the peers norfair and ByteTrack.

Run with ``make bench`` (installs the peers into .venv-bench) or directly:
``python benchmarks/track_speed.py [--data ../shared/data/mot15] [--repeats 3]``.
Times only the trackers' update calls on detections loaded beforehand; prints frames/s (median of
``--repeats`` runs) and each peer's ratio to lookalike's SORT.
"""

from __future__ import annotations

import argparse
import sys

import numpy as np
from _common import SHARED_DATA, median_seconds

from lookalike.geometry import xywh_to_xyxy
from lookalike.io import find_sequences, frames_from_table, read_mot
from lookalike.trackers import Sort


def load(root):
    seqs = []
    for s in find_sequences(root):
        seqs.append(list(frames_from_table(read_mot(s.det_path), s.length, s.frame_rate)))
    return seqs


def run_lookalike(seqs):
    for frames in seqs:
        tracker = Sort()
        for f in frames:
            tracker.update(f)


def peer_runners(seqs):
    runners = {}
    xyxy = [[(xywh_to_xyxy(f.detections.xywh), f.detections.score) for f in frames] for frames in seqs]
    try:
        import norfair

        def run_norfair():
            for frames in xyxy:
                tracker = norfair.Tracker(distance_function="iou", distance_threshold=0.7)
                for boxes, scores in frames:
                    dets = [norfair.Detection(points=b.reshape(2, 2), scores=np.array([s, s]))
                            for b, s in zip(boxes, scores)]
                    tracker.update(detections=dets)

        runners["norfair (iou, threshold 0.7)"] = run_norfair
    except ImportError:
        print("norfair not installed: skipped (make bench installs it)")
    try:
        import supervision as sv

        def run_bytetrack():
            for frames in xyxy:
                tracker = sv.ByteTrack()
                for boxes, scores in frames:
                    det = sv.Detections(xyxy=boxes.reshape(-1, 4), confidence=scores,
                                        class_id=np.zeros(len(boxes), int))
                    tracker.update_with_detections(det)

        runners["supervision ByteTrack"] = run_bytetrack
    except ImportError:
        print("supervision not installed: skipped (make bench installs it)")
    return runners


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--data", default=str(SHARED_DATA / "mot15"))
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args()
    try:
        seqs = load(args.data)
    except FileNotFoundError:
        print(f"MOT15 data not found at {args.data}: nothing to measure")
        return 0
    n_frames = sum(len(s) for s in seqs)
    print(f"{len(seqs)} sequences, {n_frames} frames, median of {args.repeats} runs, tracker time only")
    base = n_frames / median_seconds(lambda: run_lookalike(seqs), args.repeats)
    print(f"{'lookalike sort':34s} {base:10,.0f} frames/s")
    for name, run in peer_runners(seqs).items():
        fps = n_frames / median_seconds(run, args.repeats)
        print(f"{name:34s} {fps:10,.0f} frames/s   sort is {base / fps:5.1f}x faster")
    return 0


if __name__ == "__main__":
    sys.exit(main())
