"""HOG block descriptors of the cascade detector from integral histograms: row gathers for windows anywhere
(:func:`block_features_rows`) and strided slices for a grid of windows (:func:`block_features_grid`), bit for bit."""

from __future__ import annotations

import numpy as np

from lookalike.vision.hog_features import BINS, integral_maps, orientation_maps
from lookalike.vision.hog_kernels import compiled


def _output(k: int, n_blocks: int, columns: np.ndarray | None) -> tuple[np.ndarray | None, np.ndarray]:
    """The selected columns (int64, or None for all) and the float32 result: ``(k, n_blocks * 36)``, or
    ``(k, len(columns))`` column-major, as ``features[:, columns]`` gives them."""
    if columns is None:
        return None, np.empty((k, n_blocks * 4 * BINS), np.float32)
    cols = np.asarray(columns, np.int64)
    return cols, np.empty((k, len(cols)), np.float32, "F")


def _block_norms(cells: np.ndarray, area: np.ndarray) -> np.ndarray:
    """``sqrt(sum of squares) + area`` of each block from its cells ``(2, 2, BINS, ...)``, summed as numpy's pairwise
    summation sums a row of 36 values, so bit for bit ``np.sqrt((flat * flat).sum(axis=-1)) + area``."""
    sq = cells * cells
    n = 4 * BINS  # numpy's pairwise summation of 8 <= n <= 128 values
    v = [sq[j // (2 * BINS), (j // BINS) % 2, j % BINS] for j in range(n)]
    acc = [v[j] + v[j + 8] for j in range(8)]
    for i in range(16, n - n % 8, 8):
        for j in range(8):
            acc[j] += v[i + j]
    total = (acc[0] + acc[1]) + (acc[2] + acc[3])
    total += (acc[4] + acc[5]) + (acc[6] + acc[7])
    for j in range(n - n % 8, n):
        total += v[j]
    norm = np.sqrt(total, out=total)
    norm += area
    return norm


def block_pool(window_px: tuple[int, int], cell_px: int) -> np.ndarray:
    """``(b, 4)`` blocks ``xywh`` (px) in the window: even cell counts, aspect up to 3, stepped by half a block."""
    w, h = window_px[0] // cell_px, window_px[1] // cell_px
    blocks = set()
    for bw in range(2, w + 1, 2):
        for bh in range(2, h + 1, 2):
            if max(bw, bh) > 3 * min(bw, bh):
                continue
            sx, sy = max(1, bw // 2), max(1, bh // 2)
            for y in range(0, h - bh + 1, sy):
                for x in range(0, w - bw + 1, sx):
                    blocks.add((x * cell_px, y * cell_px, bw * cell_px, bh * cell_px))
    return np.array(sorted(blocks), dtype=np.int64)


def block_features_rows(rows: np.ndarray, width: int | np.ndarray, blocks: np.ndarray, ox: np.ndarray,
                         oy: np.ndarray, unit_px: int, columns: np.ndarray | None = None,
                         offset: np.ndarray | None = None) -> np.ndarray:
    """``(k, b * 36)`` float32 descriptors of ``blocks (b, 4)`` (px) for windows at ``ox, oy (k,)`` (px) of an integral
    as ``rows ((H+1) * width, BINS)`` (one row per corner, ``unit_px`` pixels apart); with ``columns``, only those.
    Stacked integrals (pyramid levels) take a per-window ``width (k,)`` and ``offset (k,)`` (first row). Compiled
    when numba is there, the same operations in the same order."""
    k, d = len(ox), 4 * BINS
    cols, out = _output(k, len(blocks), columns)
    ox, oy = np.asarray(ox, np.int64), np.asarray(oy, np.int64)
    kernels = compiled() if cols is not None and rows.dtype == np.float32 else None
    if kernels is not None and cols is not None:
        kernels["block_columns"](
            np.ascontiguousarray(rows), np.ascontiguousarray(np.broadcast_to(np.asarray(width, np.int64), (k,))),
            np.zeros(k, np.int64) if offset is None else np.ascontiguousarray(offset, np.int64),
            np.ascontiguousarray(ox), np.ascontiguousarray(oy), unit_px, np.ascontiguousarray(blocks, np.int64),
            cols // d, cols % d, out)
        return out
    per_window = np.ndim(width) > 0
    wide = np.asarray(width, np.int64)[:, None] if per_window else width
    chunk = max(1, 65536 // max(k, 1))  # blocks per gather: bounds the (3, 3, k, chunk, BINS) corner array
    for j0 in range(0, len(blocks), chunk):
        bx, by, bw, bh = np.asarray(blocks[j0 : j0 + chunk], np.int64).T
        hw, hh = bw // 2 // unit_px, bh // 2 // unit_px
        base = ((oy[:, None] + by) // unit_px) * wide + (ox[:, None] + bx) // unit_px  # (k, b)
        if offset is not None:
            base += np.asarray(offset, np.int64)[:, None]
        down = hh * wide  # corner rows between a block's cell rows: (b,) or (k, b)
        # (3, 3, k, b, BINS) corners, one contiguous (k, b, BINS) slab per corner of the 2×2 cells
        c = np.take(rows, np.arange(3)[:, None, None, None] * down + np.arange(3)[:, None, None] * hw + base, axis=0)
        cells = c[1:, 1:] - c[:-1, 1:]  # (2, 2, k, b, BINS): cell row, cell column, window, block, bin
        cells -= c[1:, :-1]
        cells += c[:-1, :-1]
        denom = _block_norms(cells.transpose(0, 1, 4, 2, 3), (bw * bh).astype(cells.dtype))  # (k, b)
        if cols is None:
            whole = out.reshape(k, len(blocks), 2, 2, BINS)[:, j0 : j0 + len(bw)]
            np.divide(cells.transpose(2, 3, 0, 1, 4), denom[:, :, None, None, None], out=whole)
            continue
        sel = np.flatnonzero((cols >= j0 * d) & (cols < (j0 + len(bw)) * d))
        block, local = cols[sel] // d - j0, cols[sel] % d
        picked = cells[local // (2 * BINS), (local // BINS) % 2, :, block, local % BINS]  # (len(sel), k)
        out[:, sel] = picked.T / denom[:, block]
    return out


def cumsum_rows(a: np.ndarray) -> np.ndarray:
    """``np.cumsum(a, axis=0)`` (the same sequential sums) as one vector add per row: faster on images."""
    out = np.empty_like(a)
    if len(a):
        out[0] = a[0]
    for y in range(1, len(a)):
        np.add(out[y - 1], a[y], out=out[y])
    return out


def cell_integral32(hist: np.ndarray) -> np.ndarray:
    """``(ny + 1, nx + 1, bins)`` float32 integral (summed in float64, first row and column zero) of cell histograms
    ``hist (ny, nx, bins)``; compiled when numba is there, the same sums in the same order."""
    h = np.ascontiguousarray(hist, dtype=np.float64)
    kernels = compiled()
    if kernels is not None:
        out = np.empty((h.shape[0] + 1, h.shape[1] + 1, h.shape[2]), np.float32)
        kernels["integral32"](h, out)
        return out
    integral = np.zeros((h.shape[0] + 1, h.shape[1] + 1, h.shape[2]))
    np.cumsum(cumsum_rows(h), axis=1, out=integral[1:, 1:])
    return integral.astype(np.float32)


def block_features_grid(planes: np.ndarray, blocks: np.ndarray, grid: tuple[int, int], stride: int,
                         unit_px: int, columns: np.ndarray | None = None) -> np.ndarray:
    """:func:`block_features_rows` for a ``grid`` (rows, columns) of windows ``stride`` corners apart of a float32
    integral ``planes (BINS, H+1, W+1)``, by strided slices; bit for bit the gathers' values."""
    ny, nx = grid
    k, d = ny * nx, 4 * BINS
    cols, out = _output(k, len(blocks), columns)
    phases: dict[tuple[int, int], np.ndarray] = {}  # planes[:, py::stride, px::stride], contiguous

    def corner_grid(y: int, x: int) -> np.ndarray:
        key = (y % stride, x % stride)
        if key not in phases:
            phases[key] = np.ascontiguousarray(planes[:, key[0] :: stride, key[1] :: stride])
        return phases[key][:, y // stride : y // stride + ny, x // stride : x // stride + nx]

    all_blocks = np.asarray(blocks, np.int64)
    needed = np.arange(len(all_blocks)) if cols is None else np.unique(cols // d)
    cells = np.empty((2, 2, BINS, len(needed), ny, nx), np.float32)  # cell row, cell column, bin, block, window
    for i, (bx, by, bw, bh) in enumerate(all_blocks[needed].tolist()):
        x0, y0, hw, hh = bx // unit_px, by // unit_px, bw // 2 // unit_px, bh // 2 // unit_px
        corner = [[corner_grid(y0 + r * hh, x0 + c * hw) for c in range(3)] for r in range(3)]
        for r in range(2):
            for c in range(2):
                cell = cells[r, c, :, i]
                np.subtract(corner[r + 1][c + 1], corner[r][c + 1], out=cell)
                cell -= corner[r + 1][c]
                cell += corner[r][c]
    area = (all_blocks[needed, 2] * all_blocks[needed, 3]).astype(np.float32)
    denom = _block_norms(cells, area[:, None, None])  # (block, ny, nx)
    if cols is None:
        np.divide(cells.transpose(4, 5, 3, 0, 1, 2), denom.transpose(1, 2, 0)[:, :, :, None, None, None],
                  out=out.reshape(ny, nx, len(all_blocks), 2, 2, BINS))
    else:
        block, local = np.searchsorted(needed, cols // d), cols % d
        picked = cells[local // (2 * BINS), (local // BINS) % 2, local % BINS, block]  # (len(cols), ny, nx)
        out[:] = (picked / denom[block]).reshape(len(cols), k).T
    return out


def window_features(windows: np.ndarray, blocks: np.ndarray) -> np.ndarray:
    """Pooled descriptors ``(n, b * 36)`` of ``windows (n, h+2, w+2)`` grey crops with a 1-px margin."""
    wins = np.asarray(windows, dtype=np.float32)
    if wins.ndim != 3 or len(wins) == 0:
        return np.zeros((0, len(blocks) * 4 * BINS), np.float32)
    n, hh, ww = wins.shape
    # Windows side by side: one gradient pass and one integral; each 1-px margin keeps its gradients its own.
    tiled = wins.transpose(1, 0, 2).reshape(hh, n * ww)
    integral = integral_maps(orientation_maps(tiled))
    rows = np.ascontiguousarray(integral.transpose(1, 2, 0)).reshape(-1, BINS)
    return block_features_rows(rows, integral.shape[2], blocks, np.arange(n, dtype=np.int64) * ww + 1,
                               np.ones(n, dtype=np.int64), 1)


__all__ = ["block_features_grid", "block_features_rows", "block_pool", "cell_integral32",
           "cumsum_rows", "window_features"]
