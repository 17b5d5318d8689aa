"""Speed of the pixels → identities pipeline (vision/pipeline.py) on 640x480 rendered robot frames, one core.

    python benchmarks/pixel_pipeline_speed.py [--preset m5n3] [--frames 150] [--seed 700000]
                                              [--detect-scale 1.0] [--detector-model F] [--heading-model F]

Renders a held-out sequence of the preset (the observer's field of view set to the camera's, as in
``lookalike bench pixels``; rendering is not timed), then times per frame: the detector alone, the
heading classifier on the detected boxes, the whole perception (detector + heading + ground
projection) and the whole pipeline with each identifier (perception + identification), in CPU time of this process
on one thread (``time.process_time``; OpenCV and BLAS on one thread). Target (issue 45): the pipeline with ``set``
(HOG + heading SVM + ``set``) at least 60 frames/s.
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):  # one core: before numpy loads
    os.environ.setdefault(_var, "1")

import numpy as np  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _common import report_target  # noqa: E402

from lookalike.sim import preset, simulate_robots
from lookalike.sim.robot_camera import identifier_settings, pixel_camera, world_for_camera
from lookalike.vision.pipeline import IDENTIFIERS, PipelineConfig, RobotPipeline
from lookalike.viz.robot_pixels import render_robot_frames


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--preset", default="m5n3")
    ap.add_argument("--frames", type=int, default=150)
    ap.add_argument("--seed", type=int, default=700_000)
    ap.add_argument("--detect-scale", type=float, default=1.0)
    ap.add_argument("--detector-model", default=None)
    ap.add_argument("--heading-model", default=None)
    args = ap.parse_args()
    import cv2

    cv2.setNumThreads(1)
    camera = pixel_camera()
    seq = simulate_robots(world_for_camera(preset(args.preset), camera), args.frames, args.seed)
    frames = list(render_robot_frames(seq, camera, seed=seq.seed))
    base = RobotPipeline.from_files(args.detector_model, args.heading_model, camera,
                                    PipelineConfig(detect_scale=args.detect_scale))
    yaw = seq.arrays.observer[:, 2]

    t0 = time.process_time()
    boxes = [base.detector(f.image).xywh for f in frames] if args.detect_scale == 1.0 else None
    t_det = time.process_time() - t0
    t0 = time.process_time()
    dets = [base.perceive(f.image, float(yaw[k])) for k, f in enumerate(frames)]
    t_perceive = time.process_time() - t0
    t0 = time.process_time()
    for f, d in zip(frames, dets):
        if len(d):
            base.heading(f.image, d.xywh)
    t_head = time.process_time() - t0
    n = len(frames)
    print(f"{args.preset}, {n} frames of 640x480, detect scale {args.detect_scale}, "
          f"{sum(len(d) for d in dets)} detections kept")
    if boxes is not None:
        print(f"  detector alone           {1000 * t_det / n:7.1f} ms/frame  {n / t_det:7.1f} frames/s "
              f"({np.mean([len(b) for b in boxes]):.2f} boxes/frame before the score threshold)")
    print(f"  heading classifier       {1000 * t_head / n:7.1f} ms/frame  {n / t_head:7.1f} frames/s")
    print(f"  perception (all of it)   {1000 * t_perceive / n:7.1f} ms/frame  {n / t_perceive:7.1f} frames/s")
    for name in IDENTIFIERS:
        cfg = PipelineConfig(identifier=name, n_agents=seq.config.n_agents, max_detections=seq.config.max_detections,
                             detect_scale=args.detect_scale, identifier_params=identifier_settings(name, camera))
        pipe = RobotPipeline(base.detector, base.heading, camera, cfg)
        t0 = time.process_time()
        for k, f in enumerate(frames):
            fr = seq.frame(k)
            pipe.update(f.image, fr.beacons, fr.time, float(yaw[k]))
        t = time.process_time() - t0
        print(f"  pipeline with {name:<10} {1000 * t / n:7.1f} ms/frame  {n / t:7.1f} frames/s")
        if name == "set":
            report_target("robot pixel pipeline (HOG + heading SVM + set), 640x480, frames/s of CPU on one core",
                          n / t, 60)


if __name__ == "__main__":
    main()
