"""The synthetic detector model of the ``mot17-synth`` sets: real ground truth seen through noise."""

from __future__ import annotations

import numpy as np

from lookalike.types.mot_table import MotTable


def synthesize_detections(gt: MotTable, length: int, image_size: tuple[int, int], rng: np.random.Generator, *,
                          noise: float = 0.05, miss_rate: float = 0.1, min_visibility: float = 0.25,
                          false_positives_per_frame: float = 0.5) -> tuple[list[np.ndarray], list[np.ndarray]]:
    """Per-frame boxes ``(n, 4)`` px and scores ``(n,)`` of a synthetic detector on MOT17 ground truth ``gt``: a
    considered pedestrian at least ``min_visibility`` visible is missed with probability ``miss_rate``, else seen with
    noise of std ``noise``·[w, h, w/2, h/2], scored U[0.6, 1]; plus Poisson(``false_positives_per_frame``) boxes
    uniform over the image (``(width, height)`` px), sized as a random true box, scored U[0.3, 0.8]."""
    if gt.extra.shape[1] < 2:
        raise ValueError("gt: expected MOT17 ground truth with class and visibility columns")
    person = (gt.conf != 0) & (gt.extra[:, 0] == 1)
    visible = person & (gt.extra[:, 1] >= min_visibility)
    sizes = gt.xywh[person, 2:4]
    if not len(sizes):
        raise ValueError("gt: no considered pedestrian boxes")
    width, height = image_size
    xywh, score = [], []
    for k in range(1, length + 1):
        truth = gt.xywh[visible & (gt.frame == k)]
        seen = truth[rng.random(len(truth)) >= miss_rate]
        scale = np.column_stack([seen[:, 2], seen[:, 3], seen[:, 2] / 2, seen[:, 3] / 2])
        boxes = seen + rng.normal(0.0, 1.0, seen.shape) * noise * scale
        n_fp = rng.poisson(false_positives_per_frame)
        fp_size = sizes[rng.integers(0, len(sizes), n_fp)]
        fp = np.column_stack([rng.uniform(0, 1, (n_fp, 2)) * np.maximum([width, height] - fp_size, 1.0), fp_size])
        boxes = np.vstack([boxes, fp])
        boxes[:, 2:] = np.maximum(np.abs(boxes[:, 2:]), 1.0)
        conf = np.concatenate([rng.uniform(0.6, 1.0, len(seen)), rng.uniform(0.3, 0.8, n_fp)])
        order = rng.permutation(len(boxes))
        xywh.append(boxes[order])
        score.append(conf[order])
    return xywh, score


__all__ = ["synthesize_detections"]
