"""Association of large frames in batches: the track-detection pairs that could ever match, found with a k-d tree
instead of a dense matrix, and the connected groups they form, packed into batches of bounded dense size.

A plan's stages only match pairs that overlap or lie within a track's re-identification reach, so a frame's problem
falls apart into independent groups of tracks and detections; solving each group (or several together) gives the
whole frame's matches with memory linear in the number of boxes."""

from __future__ import annotations

from collections.abc import Callable, Iterator

import numpy as np

from lookalike.association.stages import Matching, Stage, run_plan

__all__ = ["batches", "near_pairs", "overlapping_pairs", "pair_iou", "run_in_batches"]


def _pairs(lists: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    counts = np.fromiter((len(x) for x in lists), dtype=np.int64, count=len(lists))
    i = np.repeat(np.arange(len(lists)), counts)
    j = np.fromiter((v for x in lists for v in x), dtype=np.int64, count=int(counts.sum()))
    return i, j


def overlapping_pairs(a_xywh: np.ndarray, b_xywh: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(i, j)``: every pair of boxes ``a (k, 4)`` and ``b (n, 4)`` (left, top, width, height; pixels) whose
    rectangles share area (IoU > 0), found with a k-d tree in memory linear in the pairs."""
    if not len(a_xywh) or not len(b_xywh):
        return np.zeros(0, np.int64), np.zeros(0, np.int64)
    from scipy.spatial import cKDTree  # imported on first use

    a_half, b_half = a_xywh[:, 2:4] / 2, b_xywh[:, 2:4] / 2
    a_c, b_c = a_xywh[:, :2] + a_half, b_xywh[:, :2] + b_half
    reach = np.max(a_half, axis=1) + float(np.max(b_half))  # Chebyshev radius that covers every overlap
    i, j = _pairs(cKDTree(b_c).query_ball_point(a_c, reach, p=np.inf))
    keep = np.all(np.abs(a_c[i] - b_c[j]) < a_half[i] + b_half[j], axis=1)
    return i[keep], j[keep]


def near_pairs(a_centres: np.ndarray, radius: np.ndarray, b_centres: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(i, j)``: the pairs whose centres ``a (k, 2)`` and ``b (n, 2)`` (pixels) lie within ``radius[i]`` pixels."""
    if not len(a_centres) or not len(b_centres):
        return np.zeros(0, np.int64), np.zeros(0, np.int64)
    from scipy.spatial import cKDTree

    ok = np.isfinite(radius) & np.all(np.isfinite(a_centres), axis=1)
    rows = np.flatnonzero(ok)
    i, j = _pairs(cKDTree(b_centres).query_ball_point(a_centres[rows], radius[rows]))
    return rows[i], j


def batches(n_rows: int, n_cols: int, i: np.ndarray, j: np.ndarray,
            budget: int) -> Iterator[tuple[np.ndarray, np.ndarray]]:
    """Rows (tracks) and columns (detections) linked by the pairs ``(i, j)``, as ``(rows, columns)`` index arrays
    (ascending) of connected groups packed together while ``len(rows) * len(columns) <= budget`` (a group larger
    than the budget comes alone). Rows and columns on no pair are left out: nothing can match them."""
    if not len(i):
        return
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    size = n_rows + n_cols
    graph = coo_matrix((np.ones(len(i), np.int8), (i, j + n_rows)), shape=(size, size))
    _, label = connected_components(graph, directed=False)
    linked = np.zeros(size, bool)
    linked[i] = True
    linked[j + n_rows] = True
    nodes = np.flatnonzero(linked)
    nodes = nodes[np.argsort(label[nodes], kind="stable")]
    cuts = np.flatnonzero(np.diff(label[nodes])) + 1
    rows: list[np.ndarray] = []
    cols: list[np.ndarray] = []
    n_r = n_c = 0
    for group in np.split(nodes, cuts):
        g_rows, g_cols = group[group < n_rows], group[group >= n_rows] - n_rows
        if rows and (n_r + len(g_rows)) * (n_c + len(g_cols)) > budget:
            yield np.sort(np.concatenate(rows)), np.sort(np.concatenate(cols))
            rows, cols, n_r, n_c = [], [], 0, 0
        rows.append(g_rows)
        cols.append(g_cols)
        n_r, n_c = n_r + len(g_rows), n_c + len(g_cols)
    if rows:
        yield np.sort(np.concatenate(rows)), np.sort(np.concatenate(cols))


def pair_iou(a_xywh: np.ndarray, b_xywh: np.ndarray) -> np.ndarray:
    """IoU of the boxes ``a[m]`` and ``b[m]`` pair by pair (``(m, 4)`` each; left, top, width, height): ``(m,)``,
    0 where the union is empty."""
    side = np.minimum(a_xywh[:, :2] + a_xywh[:, 2:4], b_xywh[:, :2] + b_xywh[:, 2:4])
    side -= np.maximum(a_xywh[:, :2], b_xywh[:, :2])
    np.maximum(side, 0.0, out=side)
    inter = side[:, 0] * side[:, 1]
    union = a_xywh[:, 2] * a_xywh[:, 3] + b_xywh[:, 2] * b_xywh[:, 3] - inter
    out: np.ndarray = np.divide(inter, union, out=np.zeros_like(inter), where=union > 0)
    return out


def run_in_batches(n_rows: int, n_cols: int, i: np.ndarray, j: np.ndarray, budget: int,
                   plan: Callable[[np.ndarray, np.ndarray], list[Stage]]) -> Matching:
    """The matching of ``n_rows`` tracks and ``n_cols`` detections when only the pairs ``(i, j)`` can match:
    ``plan(rows, cols)``'s stages (indices local to the batch) run on each of :func:`batches`' batches in turn."""
    matching = Matching.empty(n_rows, n_cols)
    for rows, cols in batches(n_rows, n_cols, i, j, budget):
        part = run_plan(plan(rows, cols), len(rows), len(cols))
        hit = part.det_of_track >= 0
        matching.det_of_track[rows[hit]] = cols[part.det_of_track[hit]]
        matching.free[cols] = part.free
        matching.stage_of_track[rows] = part.stage_of_track
    return matching
