"""HOG cascade detector speed (frames/s on 640x480, one core) and precision/recall at IoU 0.5 on rendered
test frames (seeds disjoint from training).

    python benchmarks/detector_speed.py [--model det.npz | --save det.npz] [--frames 40] [--train-frames 150]
                                        [--stages 20] [--negatives 1000] [--no-mining]

Without --model, a cascade is trained on rendered robots first (train-detector's code path).
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from lookalike.cli.vision import negative_sampler, rendered_detector_data
from lookalike.geometry.boxes import iou_matrix
from lookalike.association import assign
from lookalike.vision.hog_cascade import CascadeConfig, HogCascade, train_cascade
from lookalike.vision.hog_features import augment_windows


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--model")
    ap.add_argument("--frames", type=int, default=40)
    ap.add_argument("--train-frames", type=int, default=150)
    ap.add_argument("--stages", type=int, default=20)
    ap.add_argument("--negatives", type=int, default=1000, help="hard negatives per stage")
    ap.add_argument("--no-mining", action="store_true", help="random background windows only (no scene mining)")
    ap.add_argument("--save", help="write the trained model here")
    args = ap.parse_args()
    import cv2

    cv2.setNumThreads(1)
    if args.model:
        model = HogCascade.load(args.model)
    else:
        cfg = CascadeConfig(stages=args.stages, negatives_per_stage=args.negatives)
        heights = (cfg.min_height_px, cfg.max_height_px)
        t = time.perf_counter()
        pos, frames, truths = rendered_detector_data(args.train_frames, 1, cfg.window_px, height_px=heights)
        extra = augment_windows(pos[:, 1:-1, 1:-1], 2, np.random.default_rng(0))
        pos = np.concatenate([pos, np.pad(extra, ((0, 0), (1, 1), (1, 1)), mode="edge")])
        model = train_cascade(pos, negative_sampler(frames, truths, cfg.window_px, heights), cfg,
                              progress=lambda k, m: print(f"  stage {k + 1}: {m}", flush=True),
                              scenes=() if args.no_mining else list(zip(frames, truths)))
        if args.save:
            model.save(args.save)
        print(f"trained {len(model.stages)} stages on {len(pos)} positives in {time.perf_counter() - t:.0f} s")
    from lookalike.geometry.camera import Camera
    from lookalike.sim.render_robots import RobotRenderer

    renderer = RobotRenderer(camera=Camera.default(640, 480), seed=424242)
    rng = np.random.default_rng(424242)
    half_fov = np.arctan(320 / renderer.camera.intrinsics.fx)
    images, gts = [], []
    for _ in range(args.frames):
        n = int(rng.integers(1, 5))
        depth = rng.uniform(1.0, 5.0, n)
        f = renderer.render(np.column_stack([depth, depth * np.tan(rng.uniform(-half_fov, half_fov, n))]),
                            rng.uniform(-np.pi, np.pi, n))
        images.append(f.image)
        gts.append(f.xywh[f.visible >= 0.5])
    t = time.perf_counter()
    dets = [model(img) for img in images]
    dt = time.perf_counter() - t
    print(f"detector speed: {len(images) / dt:.1f} frames/s on 640x480 ({1000 * dt / len(images):.1f} ms/frame)")
    for thr in (0.3, 0.5, 0.7, 0.9):
        tp = fp = fn = 0
        for d, gt in zip(dets, gts):
            boxes = d.xywh[d.score >= thr]
            if len(boxes) and len(gt):
                cost = 1.0 - iou_matrix(boxes, gt)
                m = assign(np.where(cost <= 0.5, cost, np.inf), 0.5).matches
                k = len(m)
            else:
                k = 0
            tp, fp, fn = tp + k, fp + len(boxes) - k, fn + len(gt) - k
        print(f"score >= {thr}: precision {tp / max(tp + fp, 1):.3f}, recall {tp / max(tp + fn, 1):.3f} "
              f"(IoU 0.5, {tp + fn} robots)")


if __name__ == "__main__":
    main()
