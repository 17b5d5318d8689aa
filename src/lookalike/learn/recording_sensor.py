"""The simulator's detector model (``SensorConfig``) measured on labelled recordings with truth."""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence

import numpy as np

from lookalike.sim import RobotArrays
from lookalike.sim.robots_config import ObserverConfig, SensorConfig

MAX_CONCENTRATION = 1000.0  # Beta a + b of a saturated score


def _beta(values: np.ndarray, fallback: tuple[float, float]) -> tuple[float, float]:
    """Method-of-moments Beta parameters of ``values`` in (0, 1); ``fallback`` with fewer than 2 values."""
    if len(values) < 2:
        return fallback
    v = np.clip(values, 1e-3, 1 - 1e-3)
    mean, var = float(v.mean()), float(v.var())
    concentration = MAX_CONCENTRATION if var <= 0 else min(mean * (1 - mean) / var - 1.0, MAX_CONCENTRATION)
    concentration = max(concentration, 0.5)
    return mean * concentration, (1.0 - mean) * concentration


def _range_profile(d: np.ndarray, occlusion: np.ndarray, sensor: SensorConfig, observer: ObserverConfig
                   ) -> np.ndarray:
    """Columns ``(n, 3)`` multiplying ``p_detect, p_detect_near, p_detect_far`` in the simulator's profile."""
    near, far = sensor.best_range_m
    below = np.clip((near - d) / max(near - observer.min_range_m, 1e-9), 0.0, 1.0)
    above = np.clip((d - far) / max(observer.max_range_m - far, 1e-9), 0.0, 1.0)
    occ = np.clip(1.0 - occlusion / sensor.occlusion_hide, 0.0, 1.0)
    return np.stack([occ * (1 - below - above), occ * below, occ * above], axis=1)


def _linear_std(d: np.ndarray, err: np.ndarray) -> tuple[float, float]:
    """``(std0, std_per_m)`` >= 0 from the RMS of ``err`` in 1-metre bins of ``d`` (weighted by count)."""
    edges = np.arange(0.0, float(d.max()) + 1.0, 1.0) if len(d) else np.zeros(1)
    centre, rms, count = [], [], []
    for lo in edges:
        m = (d >= lo) & (d < lo + 1.0)
        if m.sum() >= 5:
            centre.append(float(d[m].mean()))
            rms.append(float(np.sqrt(np.mean(err[m] ** 2))))
            count.append(float(m.sum()))
    if len(centre) < 2:
        s = float(np.sqrt(np.mean(err ** 2))) if len(err) else 0.0
        return s, 0.0
    w = np.sqrt(np.asarray(count))
    A = np.stack([np.ones(len(centre)), centre], axis=1) * w[:, None]
    (a, b), *_ = np.linalg.lstsq(A, np.asarray(rms) * w, rcond=None)
    if b < 0:
        return float(np.average(rms, weights=count)), 0.0
    if a < 0:
        return 0.0, float(np.sum(np.asarray(rms) * centre * count) / np.sum(np.square(centre) * count))
    return float(a), float(b)


def fit_sensor(recordings: Sequence[RobotArrays], base: SensorConfig, observer: ObserverConfig) -> SensorConfig:
    """``base`` with false positives, detection probabilities, position and heading noise and score Betas measured
    on ``recordings``; ``ValueError`` when they hold no detection of a robot."""
    fp_count, frames = 0, 0
    tp_scores, fp_scores, features, detected = [], [], [], []
    dist, err_xy, err_heading = [], [], []
    for a in recordings:
        valid = a.det_valid
        T, N = a.visible.shape
        frames += T
        label = np.where(valid, a.det_label, -2)
        fp_count += int((label == -1).sum())
        fp_scores.append(a.det_score[label == -1])
        t, s = np.nonzero(label >= 0)
        robot = label[t, s]
        tp_scores.append(a.det_score[t, s])
        truth = a.true_position[t, robot]
        err_xy.append(a.det_position[t, s] - truth)
        dist.append(np.hypot(truth[:, 0], truth[:, 1]))
        err_heading.append(np.angle(np.exp(1j * (a.det_heading[t, s] - a.true_heading[t, robot]))))
        hit = np.zeros((T, N), dtype=bool)
        hit[t, robot] = True
        tv, rv = np.nonzero(a.visible)
        d = np.hypot(a.true_position[tv, rv, 0], a.true_position[tv, rv, 1])
        features.append(_range_profile(d, a.occlusion[tv, rv], base, observer))
        detected.append(hit[tv, rv].astype(float))
    d_all = np.concatenate(dist)
    if not len(d_all):
        raise ValueError("the recordings hold no detection of a robot to measure the detector on")
    if not sum(len(f) for f in features) or not np.isfinite(d_all).all():
        raise ValueError("the recordings carry no usable truth (robot positions and visibility) to measure "
                         "the detector on")
    X, y = np.concatenate(features), np.concatenate(detected)
    p = np.linalg.lstsq(X, y, rcond=None)[0] if len(y) else np.array([base.p_detect, base.p_detect_near,
                                                                       base.p_detect_far])
    p = np.clip(p, 0.0, 1.0)
    e = np.concatenate(err_xy)
    x0, x1 = _linear_std(d_all, e[:, 0])
    y0, y1 = _linear_std(d_all, e[:, 1])
    h = np.abs(np.concatenate(err_heading))
    flip = h > np.pi / 2
    kept = h[~flip]
    noise = 1.4826 * float(np.median(kept)) if len(kept) else base.heading_noise_rad
    return dataclasses.replace(
        base, fp_per_frame=fp_count / max(frames, 1), p_detect=float(p[0]), p_detect_near=float(p[1]),
        p_detect_far=float(p[2]), std_x0_m=x0, std_x_per_m=x1, std_y0_m=y0, std_y_per_m=y1,
        heading_classes=0, heading_flip_prob=float(flip.mean()), heading_noise_rad=noise,
        tp_score_beta=_beta(np.concatenate(tp_scores), base.tp_score_beta),
        fp_score_beta=_beta(np.concatenate(fp_scores), base.fp_score_beta),
    )


__all__ = ["fit_sensor"]
