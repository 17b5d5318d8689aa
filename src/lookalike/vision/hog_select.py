"""Choosing a trained HOG cascade's number of stages and first pyramid level, and calibrating its probability, on
held-out scenes."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, replace

import numpy as np

from lookalike._optional import needs
from lookalike.association import assign
from lookalike.geometry.boxes import iou_matrix
from lookalike.vision.hog_cascade import HogCascade


@dataclass(frozen=True)
class HeldOutScene:
    """One held-out image: ``(h, w, 3)`` BGR or ``(h, w)`` grey; ``truth (m, 4)`` and ``ignore (k, 4)`` boxes (px)."""

    image: np.ndarray
    truth: np.ndarray
    ignore: np.ndarray


@dataclass(frozen=True)
class HeldOutScore:
    """Held-out precision, recall and F1 of the first ``stages`` stages with the pyramid's smallest window
    ``min_height_px`` tall (IoU-matched detections)."""

    stages: int
    min_height_px: float
    precision: float
    recall: float
    f1: float


def match_detections(boxes: np.ndarray, truth: np.ndarray, ignore: np.ndarray,
                     iou: float = 0.5) -> tuple[np.ndarray, np.ndarray]:
    """``(hit (n,), excused (n,))`` booleans for detection ``boxes (n, 4)``: matched one-to-one to ``truth (m, 4)``
    at IoU >= ``iou``, or else matched one-to-one to an ``ignore (k, 4)`` box. Boxes in pixels."""
    if not 0 < iou <= 1:
        raise ValueError(f"iou: must be in (0, 1], got {iou}")
    boxes = np.asarray(boxes, float).reshape(-1, 4)
    hit, excused = np.zeros(len(boxes), bool), np.zeros(len(boxes), bool)
    for target, flag in ((truth, hit), (ignore, excused)):
        target = np.asarray(target, float).reshape(-1, 4)
        free = np.flatnonzero(~hit)
        if not len(free) or not len(target):
            continue
        cost = 1.0 - iou_matrix(boxes[free], target)
        matches = assign(np.where(cost <= 1.0 - iou, cost, np.inf)).matches
        flag[free[matches[:, 0]]] = True
    return hit, excused


def evaluate_held_out(model: HogCascade, scenes: Sequence[HeldOutScene],
                      iou: float = 0.5) -> tuple[HeldOutScore, np.ndarray, np.ndarray]:
    """``model``'s held-out score, and the last-stage margin ``(n,)`` and hit flag ``(n,)`` of every detection
    that is a hit or a false positive (excused ones left out)."""
    tp = fp = total = 0
    margins, labels = [], []
    for scene in scenes:
        boxes, margin = model.boxes_and_margins(scene.image)
        hit, excused = match_detections(boxes, scene.truth, scene.ignore, iou)
        tp, fp, total = tp + int(hit.sum()), fp + int((~hit & ~excused).sum()), total + len(scene.truth)
        margins.append(margin[~excused])
        labels.append(hit[~excused])
    p, r = tp / max(tp + fp, 1), tp / max(total, 1)
    f1 = 2 * p * r / (p + r) if p + r > 0 else 0.0
    score = HeldOutScore(len(model.stages), model.config.min_height_px, p, r, f1)
    return score, np.concatenate(margins), np.concatenate(labels)


def select_stages(model: HogCascade, scenes: Sequence[HeldOutScene], *, iou: float = 0.5,
                  min_stages: int | None = None, coarser_levels: int = 2,
                  f1_tolerance: float = 0.005) -> tuple[HogCascade, list[HeldOutScore]]:
    """The cascade prefix (at least ``min_stages`` stages, default half the cascade) with the best held-out
    F1, its pyramid started up to ``coarser_levels`` levels coarser where that costs at most ``f1_tolerance``
    of F1, and its probability refitted on the held-out detections; and the score of every model tried."""
    if not scenes:
        raise ValueError("scenes: need at least one held-out scene")
    if not model.stages:
        raise ValueError("model: has no stages")
    if coarser_levels < 0 or f1_tolerance < 0:
        raise ValueError(f"coarser_levels/f1_tolerance: must be >= 0, got {coarser_levels}, {f1_tolerance}")
    n = len(model.stages)
    lowest = max(1, (n + 1) // 2 if min_stages is None else min(int(min_stages), n))
    tried = [evaluate_held_out(HogCascade(model.config, model.blocks, model.stages[:k], model.calibration),
                               scenes, iou) + (k,) for k in range(n, lowest - 1, -1)]
    score, margin, label, k = max(tried, key=lambda t: (t[0].f1, t[0].stages))
    chosen = HogCascade(model.config, model.blocks, model.stages[:k], model.calibration)
    best_f1 = score.f1
    for level in range(1, coarser_levels + 1):
        cfg = model.config
        height = cfg.min_height_px * cfg.scale_step**level
        if height > cfg.max_height_px:
            break
        coarser = HogCascade(replace(cfg, min_height_px=height), model.blocks, model.stages[:k], model.calibration)
        result = evaluate_held_out(coarser, scenes, iou)
        tried.append(result + (k,))
        if result[0].f1 < best_f1 - f1_tolerance:
            break
        chosen, margin, label = coarser, result[1], result[2]
    if 0 < label.sum() < len(label):
        with needs("sklearn"):
            from sklearn.linear_model import LogisticRegression

        lr = LogisticRegression().fit(margin[:, None], label.astype(int))
        if lr.coef_[0, 0] > 0:  # a larger margin must mean a likelier target
            chosen = HogCascade(chosen.config, chosen.blocks, chosen.stages,
                                (float(lr.coef_[0, 0]), float(lr.intercept_[0])))
    return chosen, [t[0] for t in tried]
