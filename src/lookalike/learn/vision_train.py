"""Training data for the robot detector and the heading classifier, from renders or image folders."""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from lookalike._optional import needs
from lookalike.vision.heading import HeadingConfig, feature_length, heading_features

if TYPE_CHECKING:
    from lookalike.geometry.camera import Camera

IMAGE_SUFFIXES = (".png", ".jpg", ".jpeg", ".bmp", ".tif", ".tiff")
HEADING_CONFIG = HeadingConfig()  # the heading classifier's default settings


def rendered_detector_data(
    n_frames: int, seed: int, window_px: tuple[int, int], min_visible: float = 0.7,
    height_px: tuple[float, float] = (40.0, 400.0), camera: Camera | None = None,
    step: Callable[[], None] | None = None,
) -> tuple[np.ndarray, list[np.ndarray], list[np.ndarray]]:
    """Grey positive windows ``(n, h+2, w+2)`` of rendered robots (1-5 m, random headings, 1-4 per frame), the
    grey frames and their ground-truth boxes ``(m, 4)`` (px) for sampling negatives. Deterministic by ``seed``."""
    from lookalike.vision.hog_features import crop_window, to_grey

    pos: list[np.ndarray] = []
    frames: list[np.ndarray] = []
    truths: list[np.ndarray] = []
    for frame in _rendered_frames(n_frames, seed, camera):
        grey = to_grey(frame.image)
        frames.append(grey)
        truths.append(frame.xywh)
        ok = (frame.visible >= min_visible) & (frame.xywh[:, 3] >= height_px[0]) & (frame.xywh[:, 3] <= height_px[1])
        pos.extend(crop_window(grey, box, window_px) for box in frame.xywh[ok])
        if step:
            step()
    h, w = window_px[1] + 2, window_px[0] + 2
    return np.array(pos, np.float32).reshape(-1, h, w), frames, truths


def _rendered_frames(n_frames: int, seed: int, camera: Camera | None = None) -> Iterator[Any]:
    """Rendered frames of 1-4 robots 1-5 m ahead, a little beyond the field of view, random headings."""
    from lookalike.geometry.camera import Camera
    from lookalike.sim.render_robots import RobotRenderer

    cam = camera if camera is not None else Camera.default()
    renderer = RobotRenderer(camera=cam, seed=seed)
    rng = np.random.default_rng(seed)
    half_fov = np.arctan(0.5 * cam.intrinsics.width / cam.intrinsics.fx)
    for _ in range(n_frames):
        n = int(rng.integers(1, 5))
        depth = rng.uniform(1.0, 5.0, n)
        lateral = depth * np.tan(rng.uniform(-1.1 * half_fov, 1.1 * half_fov, n))
        yield renderer.render(np.column_stack([depth, lateral]), rng.uniform(-np.pi, np.pi, n))


def rendered_held_out_scenes(n_frames: int, seed: int, camera: Camera | None = None) -> list[Any]:
    """Rendered frames as ``HeldOutScene``: robots at least half visible are targets, others ignored."""
    from lookalike.vision.hog_select import HeldOutScene

    return [HeldOutScene(f.image, f.xywh[f.visible >= 0.5], f.xywh[(f.visible < 0.5) & (f.visible > 0)])
            for f in _rendered_frames(n_frames, seed, camera)]


def negative_sampler(frames: list[np.ndarray], truths: list[np.ndarray], window_px: tuple[int, int],
                     height_px: tuple[float, float], max_iou: float = 0.2
                     ) -> Callable[[int, np.random.Generator], np.ndarray]:
    """``(count, rng) -> (count, h+2, w+2)`` random windows overlapping no truth by more than ``max_iou``."""
    from lookalike.geometry.boxes import iou_matrix
    from lookalike.vision.hog_features import crop_window

    aspect = window_px[0] / window_px[1]

    def sample(count: int, rng: np.random.Generator) -> np.ndarray:
        out: list[np.ndarray] = []
        while len(out) < count:
            k = int(rng.integers(len(frames)))
            img, gt = frames[k], truths[k]
            hh = float(np.exp(rng.uniform(*np.log(height_px))))
            hh = min(hh, img.shape[0] - 1.0)
            ww = hh * aspect
            box = np.array([[rng.uniform(0, max(1.0, img.shape[1] - ww)), rng.uniform(0, img.shape[0] - hh), ww, hh]])
            if len(gt) and iou_matrix(box, gt).max() > max_iou:
                continue
            out.append(crop_window(img, box[0], window_px, pad=0.0))
        return np.array(out, np.float32)

    return sample


def _read_grey(path: Path) -> np.ndarray:
    with needs("cv2"):
        import cv2

    from lookalike.vision.hog_features import as_bgr_image, to_grey

    img = cv2.imread(str(path), cv2.IMREAD_UNCHANGED)
    if img is None:
        raise ValueError(f"{path}: not a readable image")
    return to_grey(as_bgr_image(img, str(path)))


def folder_detector_data(folder: Path, window_px: tuple[int, int]) -> tuple[np.ndarray, list[np.ndarray]]:
    """Positive windows from ``folder/positives`` (resized) and negative images from ``folder/negatives``."""
    with needs("cv2"):
        import cv2

    def images(sub: str) -> list[Path]:
        d = folder / sub
        if not d.is_dir():
            raise ValueError(f"{folder}: needs a '{sub}' subfolder of images")
        files = sorted(p for p in d.iterdir() if p.suffix.lower() in IMAGE_SUFFIXES)
        if not files:
            raise ValueError(f"{d}: no images ({', '.join(IMAGE_SUFFIXES)})")
        return files

    size = (window_px[0] + 2, window_px[1] + 2)
    pos = np.array([cv2.resize(_read_grey(p), size, interpolation=cv2.INTER_AREA) for p in images("positives")])
    negs = [_read_grey(p) for p in images("negatives")]
    return pos.astype(np.float32), negs


Step = Callable[[str, int], Callable[[int, str], None]]


def _no_step(description: str, total: int) -> Callable[[int, str], None]:
    return lambda done, note: None


def train_robot_detector(data: Path | None, frames: int, stages: int, negatives: int, copies: int, seed: int,
                         validation_frames: int, step: Step = _no_step) -> tuple[Any, int, list[Any]]:
    """Train the HOG cascade on ``data`` (``positives/``, ``negatives/``) or ``frames`` rendered frames, keep the
    prefix with the best held-out F1 on ``validation_frames`` renders; ``(model, stages trained, candidates tried)``."""
    from lookalike.vision.hog_cascade import CascadeConfig, train_cascade
    from lookalike.vision.hog_features import augment_windows
    from lookalike.vision.hog_select import select_stages

    config = CascadeConfig(stages=stages, negatives_per_stage=negatives)
    if data is not None:
        config = dataclasses.replace(config, context_pad=0.0)
    if frames < 1 or copies < 0 or validation_frames < 0:
        raise ValueError(f"--frames/--copies/--validation-frames: need frames >= 1, copies >= 0 and "
                         f"validation_frames >= 0, got {frames}, {copies}, {validation_frames}")
    heights = (config.min_height_px, config.max_height_px)
    if data is not None:
        pos, neg_images = folder_detector_data(data, config.window_px)
        truths = [np.zeros((0, 4)) for _ in neg_images]
    else:
        rendering = step("rendering", frames)
        done = iter(range(1, frames + 1))
        pos, neg_images, truths = rendered_detector_data(
            frames, seed, config.window_px, height_px=heights, step=lambda: rendering(next(done), ""))
    if len(pos) < 10:
        raise ValueError(f"only {len(pos)} positive windows; need at least 10")
    rng = np.random.default_rng(seed)
    if copies:
        extra = augment_windows(pos[:, 1:-1, 1:-1], copies, rng)
        pos = np.concatenate([pos, np.pad(extra, ((0, 0), (1, 1), (1, 1)), mode="edge")])
    sampler = negative_sampler(neg_images, truths, config.window_px, heights)
    training = step(f"training on {len(pos)} positives", stages)
    model = train_cascade(pos, sampler, config, seed=seed, progress=lambda k, message: training(k + 1, message),
                          scenes=list(zip(neg_images, truths)))
    trained, tried = len(model.stages), list[Any]()
    if data is None and validation_frames:
        selecting = step("held-out selection", 1)
        model, tried = select_stages(model, rendered_held_out_scenes(validation_frames, seed + 1000003))
        selecting(1, "")
    return model, trained, tried


def rendered_heading_samples(n_frames: int, seed: int, config: HeadingConfig = HEADING_CONFIG,
                             robots_per_frame: int = 4, range_m: tuple[float, float] = (1.0, 5.0),
                             min_visible: float = 0.8, box_jitter: float = 0.05,
                             camera: Camera | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Features ``(n, d)`` and true egocentric headings ``(n,)`` (rad) of robots rendered ``range_m`` (m) ahead in the
    field of view (at least ``min_visible`` visible), boxes jittered by ``box_jitter`` × their size."""
    from lookalike.geometry.camera import Camera
    from lookalike.sim.render_robots import RobotRenderer

    if n_frames < 1 or robots_per_frame < 1:
        raise ValueError(f"n_frames/robots_per_frame: need >= 1, got {n_frames}, {robots_per_frame}")
    cam = camera if camera is not None else Camera.default()
    renderer = RobotRenderer(camera=cam, seed=seed)
    rng = np.random.default_rng(seed)
    k = cam.intrinsics
    half_fov = np.arctan(0.5 * k.width / k.fx)
    feats, heads = [], []
    for _ in range(n_frames):
        depth = rng.uniform(*range_m, robots_per_frame)
        lateral = depth * np.tan(rng.uniform(-half_fov, half_fov, robots_per_frame))
        frame = renderer.render(np.column_stack([depth, lateral]), rng.uniform(-np.pi, np.pi, robots_per_frame))
        keep = frame.visible >= min_visible
        if not keep.any():
            continue
        boxes = frame.xywh[keep].copy()
        boxes += rng.normal(0.0, box_jitter, boxes.shape) * boxes[:, [2, 3, 2, 3]]
        boxes[:, 2:] = np.maximum(boxes[:, 2:], 4.0)
        feats.append(heading_features(frame.image, boxes, config))
        heads.append(frame.heading_rad[keep])
    d = feature_length(config)
    if not feats:
        return np.zeros((0, d), np.float32), np.zeros(0)
    return np.concatenate(feats), np.concatenate(heads)


__all__ = ["IMAGE_SUFFIXES", "folder_detector_data", "negative_sampler", "rendered_detector_data",
           "rendered_heading_samples", "rendered_held_out_scenes", "train_robot_detector"]
