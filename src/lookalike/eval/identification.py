"""The robot-identification paper's metrics over per-frame labels (agent ids, or -1: a false positive) and
``(n_frames, n_agents, 2)`` positions in metres (NaN: absent or not estimated)."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np


def _flatten_labels(predicted: Sequence[np.ndarray], true: Sequence[np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
    if len(predicted) != len(true):
        raise ValueError(f"predicted_labels has {len(predicted)} frames, true_labels {len(true)}")
    p_parts, t_parts = [], []
    for k, (p, t) in enumerate(zip(predicted, true)):
        p, t = np.asarray(p).ravel(), np.asarray(t).ravel()
        if p.shape != t.shape:
            raise ValueError(f"frame {k}: predicted_labels has {p.size} labels, true_labels {t.size}")
        for name, a in (("predicted_labels", p), ("true_labels", t)):
            if a.size and (not np.issubdtype(a.dtype, np.integer) or a.min() < -1):
                raise ValueError(f"frame {k}: {name} must be integers >= -1")
        p_parts.append(p.astype(int))
        t_parts.append(t.astype(int))
    def cat(parts: list[np.ndarray]) -> np.ndarray:
        return np.concatenate(parts) if parts else np.zeros(0, int)

    return cat(p_parts), cat(t_parts)


def identification_counts(predicted_labels: Sequence[np.ndarray], true_labels: Sequence[np.ndarray]) -> tuple[int, int]:
    """(correct labels, detections) over all frames: the counts :func:`identification_success_rate` divides."""
    p, t = _flatten_labels(predicted_labels, true_labels)
    return int(np.sum(p == t)), int(p.size)


def identification_success_rate(predicted_labels: Sequence[np.ndarray], true_labels: Sequence[np.ndarray]) -> float:
    """Correct labels / detections over all frames (a false positive labelled -1 is correct; NaN: none)."""
    correct, detections = identification_counts(predicted_labels, true_labels)
    return correct / detections if detections else float("nan")


def robot_success_rate(predicted_labels: Sequence[np.ndarray], true_labels: Sequence[np.ndarray]) -> float:
    """Correct labels / detections of true robots (true label >= 0) over all frames (NaN: none)."""
    p, t = _flatten_labels(predicted_labels, true_labels)
    robots = t >= 0
    return float(np.mean(p[robots] == t[robots])) if robots.any() else float("nan")


def identification_by_agent(predicted_labels: Sequence[np.ndarray],
                            true_labels: Sequence[np.ndarray]) -> dict[int, float]:
    """Success rate per true label (-1: the false positives)."""
    p, t = _flatten_labels(predicted_labels, true_labels)
    return {int(a): float(np.mean(p[t == a] == a)) for a in np.unique(t)}


def _positions(estimated: np.ndarray, truth: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    e = np.asarray(estimated, dtype=float)
    g = np.asarray(truth, dtype=float)
    if g.ndim != 3 or g.shape[2] != 2:
        raise ValueError(f"truth must be (n_frames, n_agents, 2), got shape {g.shape}")
    if e.shape != g.shape:
        raise ValueError(f"estimated has shape {e.shape}, truth {g.shape}")
    return e, g


def localisation_error_by_agent(estimated: np.ndarray, truth: np.ndarray) -> np.ndarray:
    """Mean distance (m) per agent ``(n_agents,)`` where present and estimated (NaN: never)."""
    e, g = _positions(estimated, truth)
    d = np.linalg.norm(e - g, axis=2)
    ok = np.isfinite(d)
    count = ok.sum(axis=0)
    total = np.where(ok, d, 0.0).sum(axis=0)
    result: np.ndarray = np.divide(total, count, out=np.full(count.shape, np.nan), where=count > 0)
    return result


def localisation_error(estimated: np.ndarray, truth: np.ndarray) -> float:
    """Mean distance (m) over every (frame, agent) present and estimated (NaN: none)."""
    e, g = _positions(estimated, truth)
    d = np.linalg.norm(e - g, axis=2)
    d = d[np.isfinite(d)]
    return float(d.mean()) if d.size else float("nan")


def localisation_coverage(estimated: np.ndarray, truth: np.ndarray) -> float:
    """Fraction of (frame, agent) presences in ``truth`` that have an estimate (NaN if none)."""
    e, g = _positions(estimated, truth)
    present = np.isfinite(g).all(axis=2)
    if not present.any():
        return float("nan")
    return float(np.isfinite(e).all(axis=2)[present].mean())
