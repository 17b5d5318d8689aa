"""``iou_columns`` (boxes as columns, x and y together) equals ``iou_matrix`` bit for bit."""

from __future__ import annotations

import numpy as np

from lookalike.association.costs import iou_columns
from lookalike.geometry.boxes import iou_matrix


def test_iou_of_columns_equals_the_iou_matrix() -> None:
    rng = np.random.default_rng(0)
    for _ in range(200):
        m, n = (int(v) for v in rng.integers(0, 9, 2))
        a = np.column_stack([rng.uniform(0, 300, (m, 2)), rng.uniform(0, 80, (m, 2))])
        b = np.column_stack([rng.uniform(0, 300, (n, 2)), rng.uniform(0, 80, (n, 2))])
        if m and n and rng.random() < 0.3:  # zero-area boxes, alone and on top of each other
            a[0, 2:] = 0.0
            b[-1] = a[0]
        if n and rng.random() < 0.3:
            b[0] = a[-1] if m else b[0]
        assert np.array_equal(iou_columns(a.T, b.T), iou_matrix(a, b))
