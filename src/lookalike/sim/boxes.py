"""A 2-D box world: pedestrian-like targets moving in an image, seen by a noisy detector, with ground truth."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from lookalike.types import Detections, Frame


@dataclass(frozen=True)
class BoxSceneConfig:
    """Scene parameters; sizes in pixels, rates per frame."""

    n_targets: int = 6
    frames: int = 300
    frame_rate: float = 25.0
    image_size: tuple[int, int] = (640, 480)
    box_size: tuple[float, float] = (40.0, 100.0)
    speed_px: float = 3.0
    accel_px: float = 0.3
    position_noise_px: float = 2.0
    miss_rate: float = 0.1
    false_positives_per_frame: float = 0.5
    seed: int = 0


@dataclass(frozen=True, eq=False)
class BoxScene:
    """Simulated frames and ground truth.

    Attributes:
        frames: one :class:`Frame` per time step (detections with ``label`` = target id or -1).
        gt: ``(n, 10)`` MOTChallenge ground-truth rows (1-based frames and ids).
        config: the configuration that made it."""

    frames: list[Frame]
    gt: np.ndarray
    config: BoxSceneConfig


def simulate_boxes(config: BoxSceneConfig | None = None) -> BoxScene:
    """Simulate targets bouncing inside the image with random accelerations."""
    cfg = config or BoxSceneConfig()
    rng = np.random.default_rng(cfg.seed)
    width, height = cfg.image_size
    bw, bh = cfg.box_size
    n = cfg.n_targets
    size = np.column_stack([bw * rng.uniform(0.8, 1.2, n), bh * rng.uniform(0.8, 1.2, n)])
    lo = np.zeros(2)
    hi = np.array([width, height]) - size
    pos = rng.uniform(lo, hi)
    vel = rng.normal(0.0, cfg.speed_px, (n, 2))
    frames, gt = [], []
    for k in range(cfg.frames):
        vel = np.clip(vel + rng.normal(0.0, cfg.accel_px, (n, 2)), -2 * cfg.speed_px, 2 * cfg.speed_px)
        pos = pos + vel
        bounce = (pos < lo) | (pos > hi)
        vel[bounce] *= -1
        pos = np.clip(pos, lo, hi)
        truth = np.column_stack([pos, size])
        for i in range(n):
            gt.append([k + 1, i + 1, *truth[i], 1, 1, 1.0, -1])
        seen = rng.random(n) >= cfg.miss_rate
        boxes = truth[seen] + rng.normal(0.0, cfg.position_noise_px, (int(seen.sum()), 4)) * [1, 1, 0.5, 0.5]
        labels = np.flatnonzero(seen)
        n_fp = rng.poisson(cfg.false_positives_per_frame)
        fp_size = size[rng.integers(0, n, n_fp)] if n_fp else np.zeros((0, 2))
        fp = np.column_stack([rng.uniform(0, 1, (n_fp, 2)) * (np.array([width, height]) - fp_size), fp_size])
        xywh = np.vstack([boxes, fp])
        xywh[:, 2:] = np.abs(xywh[:, 2:])
        score = np.concatenate([rng.uniform(0.6, 1.0, len(boxes)), rng.uniform(0.3, 0.8, n_fp)])
        label = np.concatenate([labels, -np.ones(n_fp, dtype=int)])
        order = rng.permutation(len(xywh))
        det = Detections(xywh=xywh[order], score=score[order], label=label[order])
        frames.append(Frame(index=k, time=k / cfg.frame_rate, detections=det))
    return BoxScene(frames=frames, gt=np.array(gt, dtype=float).reshape(-1, 10), config=cfg)
