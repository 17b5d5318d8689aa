"""Per-frame Hungarian matching over sparse pairs, for the frames whose pairs are not one-to-one: dense matrices built
in one reused buffer (:func:`negated_matrices`) and solved in turn (:func:`solve_matrices`)."""

from __future__ import annotations

from collections.abc import Callable, Iterable, Iterator
from typing import Any

import numpy as np


def hungarian() -> Callable[..., Any]:
    """SciPy's ``linear_sum_assignment`` without importing ``scipy.optimize`` (:mod:`lookalike._lsap`)."""
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


_CHUNK = 1 << 15  # float64 entries (256 KiB) of the buffer that consecutive matrices are built in


def negated_matrices(shapes: np.ndarray, block: np.ndarray, rows: np.ndarray, cols: np.ndarray,
                     values: np.ndarray) -> Iterator[np.ndarray]:
    """``k`` dense negated matrices of ``shapes (k, 2)``: ``-0.0`` except ``-values`` at ``(rows, cols)`` of matrix
    ``block``; each a view of one reused buffer, valid until the next is asked for."""
    k = len(shapes)
    if not k:
        return
    n_cols = shapes[:, 1]
    sizes = shapes[:, 0] * n_cols
    ends = np.cumsum(sizes)
    starts = ends - sizes
    where = starts[block] + rows * n_cols[block] + cols  # every entry's place in the matrices laid end to end
    pair_at = np.searchsorted(block, np.arange(k + 1)).tolist()
    buffer = np.empty(max(_CHUNK, int(sizes.max())))
    starts_l, ends_l, shapes_l = starts.tolist(), ends.tolist(), shapes.tolist()
    m = 0
    while m < k:
        base = starts_l[m]
        stop = max(int(np.searchsorted(ends, base + len(buffer), "right")), m + 1)
        buffer[:ends_l[stop - 1] - base] = -0.0
        p0, p1 = pair_at[m], pair_at[stop]
        buffer[where[p0:p1] - base] = -values[p0:p1]
        for q in range(m, stop):
            n_r, n_c = shapes_l[q]
            yield buffer[starts_l[q] - base:ends_l[q] - base].reshape(n_r, n_c)
        m = stop


def solve_matrices(matrices: Iterable[np.ndarray]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Each matrix's minimum-cost assignment: rows and columns (local) concatenated, and the number per matrix."""
    linear_sum_assignment = hungarian()
    rows, cols = [], []
    for cost in matrices:
        r, c = linear_sum_assignment(cost)
        rows.append(r)
        cols.append(c)
    if not rows:
        empty = np.zeros(0, np.int64)
        return empty, empty, empty
    counts = np.fromiter((len(r) for r in rows), np.int64, len(rows))
    return np.concatenate(rows), np.concatenate(cols), counts
