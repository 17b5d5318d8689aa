"""Training targets and scoring shared by the association network's training code (numpy only)."""

from __future__ import annotations

import numpy as np

IGNORE = -100  # target of an empty slot (ignored by the loss)


def success_rate(prob: np.ndarray, y: np.ndarray) -> tuple[int, int]:
    """Correct and total labelled slots, per-slot argmax of ``prob (T, M, N+1)`` against ``y``."""
    used = y != IGNORE
    return int(((prob.argmax(-1) == y) & used).sum()), int(used.sum())
