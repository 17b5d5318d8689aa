"""Speed of appearance features + diver SORT on 640x480 rendered video with 4 divers, one core.

Run: ``.venv/bin/python benchmarks/diver_speed.py [--frames 300] [--features handcrafted learned]``.
Frames are rendered and detected first (not timed); the timed loop is feature extraction from the
image plus the tracker update, as on the robot after the detector, timed in CPU seconds of this
process (``time.process_time``, one thread: the figure of one core even on a shared machine; the
wall-clock rate is printed beside it). Targets (DESIGN §11, issue 22):
features + diver SORT >= 100 frames/s for each feature set; learned features >= 500 crops/s.
With ``--detector FILE.onnx`` the ONNX detector's time per frame is measured too and the end-to-end
rate (detector + features + diver SORT) printed; the tracker still gets the simulated boxes, so the
figure is the cost of a detector in the loop, not its accuracy.
"""

from __future__ import annotations

import os

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import argparse
import dataclasses
import time

import numpy as np
from _common import report_target


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--frames", type=int, default=300)
    parser.add_argument("--scenario", default="pool_four_crossing")
    parser.add_argument("--features", nargs="+", default=["handcrafted", "learned"],
                        help="handcrafted, learned or FILE.onnx (each timed)")
    parser.add_argument("--detector", default=None, help="an ONNX detection model to time in the loop")
    args = parser.parse_args()

    import cv2

    cv2.setNumThreads(1)
    from lookalike.sim.divers import DetectorModel, scenario, simulate_divers
    from lookalike.sim.divers_run import diver_extractor
    from lookalike.trackers import make_tracker
    from lookalike.types import Frame

    # Every diver stays in view and every one is detected: 4 crops per frame.
    sc = dataclasses.replace(scenario(args.scenario), frames=args.frames, leave_rate=0.0,
                             detector=DetectorModel(recall=1.0, false_positives=0.0, min_visibility=0.0))
    assert sc.n_divers == 4 and sc.image_size == (640, 480)
    scene = simulate_divers(sc)
    frames = scene.frames()
    images = [scene.image(k) for k in range(len(frames))]
    n = len(frames)
    print(f"scenario {sc.name}: {n} frames 640x480")
    detector_s = 0.0
    if args.detector:
        from lookalike.vision.onnx_detector import OnnxDetector

        detector = OnnxDetector(args.detector)
        t0 = time.process_time()
        for image in images:
            detector(image)
        detector_s = time.process_time() - t0
        print(f"detector {args.detector}: {1e3 * detector_s / n:.2f} ms per frame (CPU), {n / detector_s:.1f} frames/s")
    for name in args.features:
        extractor = diver_extractor(name)
        tracker = make_tracker("diversort")
        n_crops = 0
        feat_s = track_s = 0.0
        wall0 = time.perf_counter()
        for frame, image in zip(frames, images):
            t0 = time.process_time()
            det = frame.detections
            det = det.replace(feature=extractor(image, det.xywh) if len(det) else np.zeros((0, extractor.dim)))
            t1 = time.process_time()
            tracker.update(Frame(index=frame.index, time=frame.time, detections=det))
            t2 = time.process_time()
            feat_s += t1 - t0
            track_s += t2 - t1
            n_crops += len(det)
        wall = time.perf_counter() - wall0
        print(f"{name}: {n_crops / n:.2f} detections/frame, features {1e3 * feat_s / max(n_crops, 1):.3f} ms per crop "
              f"({1e3 * feat_s / n:.2f} ms per frame), diver SORT {1e3 * track_s / n:.2f} ms per frame (CPU); "
              f"wall clock {n / wall:.0f} frames/s")
        if name != "handcrafted":
            report_target(f"{name} features, crops/s on one core", n_crops / feat_s, 500)
        report_target(f"{name} features + diver SORT, frames/s with 4 divers", n / (feat_s + track_s), 100)
        if args.detector:
            print(f"{name}: detector + features + diver SORT {n / (detector_s + feat_s + track_s):.1f} frames/s (CPU)")


if __name__ == "__main__":
    main()
