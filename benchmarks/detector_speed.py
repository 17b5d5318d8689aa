"""HOG cascade detector speed (frames/s on 640x480, one core) and precision/recall at IoU 0.5 on rendered
frames whose seeds were not used in training (training renders seed 1).

    python benchmarks/detector_speed.py [--model det.npz | --train | --save det.npz] [--frames 100] [--train-frames 300]
                                        [--stages 20] [--negatives 1000] [--no-mining] [--split test|validation]
                                        [--select 200] [--scale-step 1.25] [--threshold 0.4] [--rounds 1] [--compare]

Frames: 1-4 robots each, 1-5 m ahead (depth), anywhere across the field of view, random headings; the
test split renders seed 424242, the validation split (for choosing settings) seed 515151. Three truths:

- ``all``: every robot at least half visible (the border or other robots hide the rest); a detection
  matching no such robot is a false positive;
- ``1-5 m``: robots whose ground distance from the camera (egocentric position) is 1-5 m and that are
  at least half visible; detections of the other robots in the image are neither hits nor false positives;
- ``1-5 m, whole``: as ``1-5 m``, and the whole robot lies inside the image (not cut by the border).

By default the shipped detector (``lookalike/vision/models_data``) is timed, and its frames/s (CPU time, one
core; the median of ``--rounds`` passes over the frames) printed as the issue-18 target (>= 30). The detector uses
its compiled kernels when numba is installed (the ``fast`` extra; ``LOOKALIKE_HOG_NUMBA=0`` turns them off); the
CPU time of the first call (imports, loading or compiling the kernels) is printed apart. ``--compare`` also times
the numpy path, rounds alternating, checks that both give the same detections and prints the ratio.

With --train (or --save), a cascade is trained on rendered robots
first (train-detector's code path), then cut to the prefix and pyramid start with the best F1 on the validation
split (as train-detector does on its own held-out renders).
--scale-step overrides the model's pyramid step at detection time.
"""

from __future__ import annotations

import argparse
import dataclasses
import os
import time

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):  # one core: before numpy loads
    os.environ.setdefault(_var, "1")

import numpy as np
from _common import report_target

from lookalike.association import assign
from lookalike.geometry.boxes import iou_matrix
from lookalike.learn.vision_train import negative_sampler, rendered_detector_data
from lookalike.vision.hog_cascade import CascadeConfig, HogCascade, train_cascade
from lookalike.vision.hog_features import augment_windows
from lookalike.vision.hog_kernels import compiled, use_compiled
from lookalike.vision.hog_select import HeldOutScene, select_stages
from lookalike.vision.pipeline import shipped_model_path

SPLIT_SEEDS = {"test": 424242, "validation": 515151}
THRESHOLDS = (0.0, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9)


def render_split(frames: int, seed: int) -> tuple[list[np.ndarray], list[dict[str, np.ndarray]]]:
    """Images and, per image, the robots in it: ``xywh`` (clipped, px), ``visible``, ``distance_m``, ``whole``."""
    from lookalike.geometry.camera import Camera
    from lookalike.sim.render_robots import RobotRenderer

    renderer = RobotRenderer(camera=Camera.default(640, 480), seed=seed)
    rng = np.random.default_rng(seed)
    k = renderer.camera.intrinsics
    half_fov = np.arctan(0.5 * k.width / k.fx)
    images, truths = [], []
    for _ in range(frames):
        n = int(rng.integers(1, 5))
        depth = rng.uniform(1.0, 5.0, n)
        f = renderer.render(np.column_stack([depth, depth * np.tan(rng.uniform(-half_fov, half_fov, n))]),
                            rng.uniform(-np.pi, np.pi, n))
        full = f.xywh_full
        whole = (full[:, 0] >= 0) & (full[:, 1] >= 0) & (full[:, 0] + full[:, 2] <= k.width) & \
                (full[:, 1] + full[:, 3] <= k.height)
        images.append(f.image)
        truths.append({"xywh": f.xywh, "visible": f.visible, "distance_m": np.hypot(*f.position_m.T),
                       "whole": whole})
    return images, truths


def _match(boxes: np.ndarray, gt: np.ndarray) -> np.ndarray:
    """``(k, 2)`` one-to-one (box, truth) pairs with IoU >= 0.5."""
    if not len(boxes) or not len(gt):
        return np.zeros((0, 2), int)
    cost = 1.0 - iou_matrix(boxes, gt)
    return assign(np.where(cost <= 0.5, cost, np.inf), 0.5).matches


def count(boxes: np.ndarray, truth: dict[str, np.ndarray], rule: str) -> tuple[int, int, int]:
    """``(true positives, false positives, misses)`` of one image's ``boxes (m, 4)`` under truth ``rule``."""
    half = truth["visible"] >= 0.5
    if rule == "all":
        scored, ignored = half, np.zeros_like(half)
    else:
        scored = half & (truth["distance_m"] >= 1.0) & (truth["distance_m"] <= 5.0)
        if rule == "whole":
            scored &= truth["whole"]
        ignored = ~scored & (truth["visible"] > 0)
    hits = _match(boxes, truth["xywh"][scored])
    rest = np.setdiff1d(np.arange(len(boxes)), hits[:, 0])
    excused = len(_match(boxes[rest], truth["xywh"][ignored]))
    return len(hits), len(boxes) - len(hits) - excused, int(scored.sum()) - len(hits)


def select(model: HogCascade, frames: int) -> HogCascade:
    """``model`` cut to the prefix with the best F1 on ``frames`` validation frames, probability refitted there."""
    images, truths = render_split(frames, SPLIT_SEEDS["validation"])
    scenes = [HeldOutScene(img, t["xywh"][t["visible"] >= 0.5], t["xywh"][(t["visible"] < 0.5) & (t["visible"] > 0)])
              for img, t in zip(images, truths)]
    chosen, table = select_stages(model, scenes)
    for s in table:
        print(f"  validation, {s.stages} stages, pyramid from {s.min_height_px:g} px: precision {s.precision:.3f}, "
              f"recall {s.recall:.3f}, F1 {s.f1:.3f}")
    print(f"kept {len(chosen.stages)} of {len(model.stages)} stages, pyramid from {chosen.config.min_height_px:g} px; "
          f"calibration {chosen.calibration}")
    return chosen


def train(args: argparse.Namespace) -> HogCascade:
    cfg = CascadeConfig(stages=args.stages, negatives_per_stage=args.negatives)
    heights = (cfg.min_height_px, cfg.max_height_px)
    t = time.perf_counter()
    pos, frames, truths = rendered_detector_data(args.train_frames, 1, cfg.window_px, height_px=heights)
    extra = augment_windows(pos[:, 1:-1, 1:-1], 2, np.random.default_rng(0))
    pos = np.concatenate([pos, np.pad(extra, ((0, 0), (1, 1), (1, 1)), mode="edge")])
    model = train_cascade(pos, negative_sampler(frames, truths, cfg.window_px, heights), cfg,
                          progress=lambda k, m: print(f"  stage {k + 1}: {m}", flush=True),
                          scenes=() if args.no_mining else list(zip(frames, truths)))
    if args.save and not args.select:
        model.save(args.save)
    print(f"trained {len(model.stages)} stages on {len(pos)} positives in {time.perf_counter() - t:.0f} s")
    return model


def time_paths(model: HogCascade, images: list[np.ndarray], rounds: int,
               compare: bool) -> tuple[dict[bool | None, list[tuple[float, float]]], dict[bool | None, list]]:
    """Per path (``None``: the default, ``False``: numpy), the (CPU, wall) seconds of each round over ``images``
    and the detections of the last round; with ``compare`` (and numba there) rounds alternate between the paths."""
    paths = [None, False] if compare and compiled() is not None else [None]
    times: dict[bool | None, list[tuple[float, float]]] = {p: [] for p in paths}
    found: dict[bool | None, list] = {}
    for _ in range(rounds):
        for p in paths:  # rounds alternate between the paths, so both meet the same load
            use_compiled(p)
            if p is False:
                model(images[0])
            t, cpu = time.perf_counter(), time.process_time()
            found[p] = [model(img) for img in images]
            times[p].append((time.process_time() - cpu, time.perf_counter() - t))
    use_compiled(None)
    return times, found


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--model", help="a model file to time (default: the shipped detector, unless --train/--save)")
    ap.add_argument("--train", action="store_true", help="train a cascade on rendered robots first")
    ap.add_argument("--frames", type=int, default=100)
    ap.add_argument("--split", choices=list(SPLIT_SEEDS), default="test")
    ap.add_argument("--train-frames", type=int, default=300)
    ap.add_argument("--stages", type=int, default=20)
    ap.add_argument("--negatives", type=int, default=1000, help="hard negatives per stage")
    ap.add_argument("--no-mining", action="store_true", help="random background windows only (no scene mining)")
    ap.add_argument("--save", help="write the trained model here")
    ap.add_argument("--scale-step", type=float, help="pyramid step at detection time (default: the model's)")
    ap.add_argument("--select", type=int, metavar="FRAMES",
                    help="keep the cascade prefix (and pyramid start) with the best F1 on this many validation "
                         "frames, probability refitted there (default: 200 after training, 0 with --model)")
    ap.add_argument("--threshold", type=float, default=0.4,
                    help="score threshold of the summary lines (0.4: the highest keeping all validation hits)")
    ap.add_argument("--rounds", type=int, default=1, help="passes over the frames; the median is reported")
    ap.add_argument("--compare", action="store_true",
                    help="also time the numpy path (rounds alternating) and check that it gives the same detections")
    args = ap.parse_args()
    if args.rounds < 1:
        ap.error(f"--rounds: must be >= 1, got {args.rounds}")
    import cv2

    cv2.setNumThreads(1)
    trained = not args.model and (args.train or args.save)
    if args.select is None:
        args.select = 200 if trained else 0
    shipped = not args.model and not trained
    model = train(args) if trained else HogCascade.load(args.model or shipped_model_path("detector"))
    if args.select:
        model = select(model, args.select)
        if args.save:
            model.save(args.save)
    if args.scale_step:
        model.config = dataclasses.replace(model.config, scale_step=args.scale_step)
    images, truths = render_split(args.frames, SPLIT_SEEDS[args.split])
    path = "compiled kernels (numba)" if compiled() is not None else "numpy (numba not installed or turned off)"
    cpu = time.process_time()
    model(images[0])  # warm-up: imports, loading (or the first time compiling) the kernels
    print(f"path: {path}; first call {time.process_time() - cpu:.2f} s of CPU time")
    times, found = time_paths(model, images, args.rounds, args.compare)
    dets = found[None]
    print(f"{args.split} split (seed {SPLIT_SEEDS[args.split]}), {len(images)} frames, scale step "
          f"{model.config.scale_step:g}, {args.rounds} round(s)")
    # One thread (cv2.setNumThreads(1); numpy's element-wise work is single-threaded): CPU time is the time
    # on one free core, wall time also counts waiting for a busy machine.
    fps = {p: len(images) / float(np.median([c for c, _ in v])) for p, v in times.items()}
    for p, v in times.items():
        label = "detector speed" if p is None else "numpy path    "
        best, wall = len(images) / min(c for c, _ in v), len(images) / float(np.median([w for _, w in v]))
        print(f"{label}: {fps[p]:.1f} frames/s on 640x480, one core, by CPU time (median; best {best:.1f}; "
              f"{1000 / fps[p]:.1f} ms/frame); by wall time {wall:.1f} frames/s")
    if False in found:
        same = all(np.array_equal(a.xywh, b.xywh) and np.array_equal(a.score, b.score)
                   for a, b in zip(found[None], found[False]))
        print(f"compiled / numpy: {fps[None] / fps[False]:.2f}x; detections {'identical' if same else 'DIFFER'}")
    if shipped:
        report_target("shipped HOG cascade frames/s on 640x480, one core (CPU time)", fps[None], 30.0)
    summary = {}
    for rule, label in (("all", "all"), ("range", "1-5 m"), ("whole", "1-5 m, whole")):
        for thr in THRESHOLDS:
            tp = fp = fn = 0
            for d, truth in zip(dets, truths):
                a, b, c = count(d.xywh[d.score >= thr], truth, rule)
                tp, fp, fn = tp + a, fp + b, fn + c
            p, r = tp / max(tp + fp, 1), tp / max(tp + fn, 1)
            print(f"{label:<13} score >= {thr:.1f}: precision {p:.3f}, recall {r:.3f} ({tp + fn} robots)")
            if abs(thr - args.threshold) < 1e-9:
                summary[label] = (p, r, tp + fn)
    for label, (p, r, n) in summary.items():
        print(f"summary {label:<13} (score >= {args.threshold:g}): precision {p:.3f}, recall {r:.3f}, {n} robots")


if __name__ == "__main__":
    main()
