"""Per-frame Hungarian matching over sparse pairs, with the exact shortcut for frames whose pairs
already form a one-to-one matching.

A frame's score matrix is zero except at its listed pairs. When no detection appears in two of a
frame's positive pairs, every maximum-score assignment contains all of them, so the Hungarian
algorithm is only run on the other frames, on the same dense matrix as before (same result, same
tie-breaking).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np


def hungarian() -> Callable[..., Any]:
    """SciPy's ``linear_sum_assignment``, loaded on first use without ``scipy.optimize`` (which takes a
    good part of a second to import; :mod:`lookalike._lsap`)."""
    from lookalike._lsap import linear_sum_assignment

    solve: Callable[..., Any] = linear_sum_assignment
    return solve


def frame_bounds(frame: np.ndarray, num_frames: int) -> np.ndarray:
    """``(F + 1,)`` offsets of each frame's run in ``frame`` (sorted 0-based frame indices)."""
    result: np.ndarray = np.searchsorted(frame, np.arange(num_frames + 1))
    return result


def conflicted_frames(frame: np.ndarray, gt_det: np.ndarray, tracker_det: np.ndarray, num_frames: int,
                      num_gt_dets: int, num_tracker_dets: int) -> np.ndarray:
    """``(F,)`` bool: frames where some detection appears in more than one of the given pairs."""
    deg_g = np.bincount(gt_det, minlength=num_gt_dets)
    deg_t = np.bincount(tracker_det, minlength=num_tracker_dets)
    shared = (deg_g[gt_det] > 1) | (deg_t[tracker_det] > 1)
    result: np.ndarray = np.bincount(frame[shared], minlength=num_frames) > 0
    return result


def dense(shape: tuple[int, int], rows: np.ndarray, cols: np.ndarray, values: np.ndarray) -> np.ndarray:
    """A ``shape`` float64 matrix, zero except ``values`` at ``(rows, cols)``."""
    out = np.zeros(shape)
    out[rows, cols] = values
    return out
