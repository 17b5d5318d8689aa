"""Per-frame Hungarian matching over sparse pairs, with the exact shortcut for frames whose pairs
already form a one-to-one matching.

A frame's score matrix is zero except at its listed pairs. When no detection appears in two of a
frame's positive pairs, every maximum-score assignment contains all of them, so the Hungarian
algorithm is only run on the other frames, on the same dense matrix as before (same result, same
tie-breaking). Those matrices are built all at once in one flat buffer (:func:`negated_blocks`) and
solved one after another (:func:`solve_blocks`), instead of one allocation and scatter per frame.
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


def negated_blocks(shapes: np.ndarray, block: np.ndarray, rows: np.ndarray, cols: np.ndarray,
                   values: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``k`` dense matrices of ``shapes`` ``(k, 2)``, negated and stored row-major one after another in one
    flat float64 buffer: ``-0.0`` everywhere (as ``-np.zeros(shape)``) except ``-values`` at ``(rows, cols)`` of
    matrix ``block`` (one entry per value). Returns the buffer and the ``(k + 1,)`` offsets of the matrices."""
    offsets = np.zeros(len(shapes) + 1, np.int64)
    np.cumsum(shapes[:, 0] * shapes[:, 1], out=offsets[1:])
    buffer = np.full(int(offsets[-1]), -0.0)
    buffer[offsets[block] + rows * shapes[block, 1] + cols] = -values
    return buffer, offsets


def solve_blocks(buffer: np.ndarray, offsets: np.ndarray,
                 shapes: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The minimum-cost assignment of each matrix of :func:`negated_blocks` (the maximum one of the
    un-negated matrix): its rows and columns (local indices) concatenated, and the number per matrix."""
    linear_sum_assignment = hungarian()
    rows, cols = [], []
    for start, stop, n_rows, n_cols in zip(offsets[:-1].tolist(), offsets[1:].tolist(), shapes[:, 0].tolist(),
                                           shapes[:, 1].tolist()):
        r, c = linear_sum_assignment(buffer[start:stop].reshape(n_rows, n_cols))
        rows.append(r)
        cols.append(c)
    if not rows:
        empty = np.zeros(0, np.int64)
        return empty, empty, empty
    counts = np.fromiter((len(r) for r in rows), np.int64, len(rows))
    return np.concatenate(rows), np.concatenate(cols), counts
