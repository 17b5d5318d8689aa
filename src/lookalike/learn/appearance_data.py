"""Labelled diver crops for the learned appearance model (numpy): cut from rendered frames at jittered ground-truth
boxes and resized to ``(width, height)`` pixels; a label is one diver of one scenario (``seed · 10 + diver id``)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from lookalike.sim.divers import DiverScenario, simulate_divers
from lookalike.vision.appearance import crop_boxes

CROP_SIZE = (64, 32)  # width, height in pixels: divers swim horizontally (boxes ~2.7:1)


@dataclass(frozen=True)
class CropSet:
    """``crops (m, h, w, 3)`` BGR uint8 and integer identity ``labels (m,)``."""

    crops: np.ndarray
    labels: np.ndarray


def diver_crops(scenarios: tuple[DiverScenario, ...], every: int = 3, size: tuple[int, int] = CROP_SIZE,
                min_visibility: float = 0.3, jitter: float = 0.08, seed: int = 0) -> CropSet:
    """Crops of every visible diver (visibility ``>= min_visibility``) in every ``every``-th frame."""
    rng = np.random.default_rng(seed)
    crops, labels = [], []
    for sc in scenarios:
        scene = simulate_divers(sc)
        for k in range(0, sc.frames, every):
            rows = scene.gt[(scene.gt[:, 0] == k + 1) & (scene.gt[:, 8] >= min_visibility)]
            if not len(rows):
                continue
            boxes = rows[:, 2:6].copy()
            scale = rng.uniform(1 - jitter, 1 + 1.5 * jitter, (len(rows), 1))
            centre = boxes[:, :2] + boxes[:, 2:] / 2 + rng.normal(0, jitter / 2, (len(rows), 2)) * boxes[:, 2:]
            boxes[:, 2:] *= scale
            boxes[:, :2] = centre - boxes[:, 2:] / 2
            crops.append(crop_boxes(scene.image(k), boxes, size))
            labels.append(sc.seed * 10 + rows[:, 1].astype(int))
    if not crops:
        raise ValueError("no visible divers in the scenarios")
    return CropSet(np.concatenate(crops), np.concatenate(labels))


__all__ = ["CROP_SIZE", "CropSet", "diver_crops"]
