"""The numba kernels of :mod:`lookalike.vision.hog_kernels` (imported only when numba is installed)."""

from __future__ import annotations

import numpy as np

from lookalike._compiled import exact_jit

_jit = exact_jit()


@_jit  # type: ignore[misc]
def cell_hist(mag: np.ndarray, ang: np.ndarray, row0: int, cell_px: int, bins: int, scale: np.float32,
              out: np.ndarray) -> None:
    """Cell histograms of one band (``mag, ang`` float32 from row ``row0``) into ``out (cell rows, cell columns,
    bins)`` float64, summed as the two ``np.bincount`` calls of the numpy path do."""
    ny, nx = out.shape[0], out.shape[1]
    rows, cols = ny * cell_px, nx * cell_px
    pi = np.float32(np.pi)
    half = np.float32(0.5)
    # 1. binning, one row at a time (a plain loop the compiler vectorises)
    w_lo = np.empty((rows, cols), np.float32)
    w_hi = np.empty((rows, cols), np.float32)
    lo = np.empty((rows, cols), np.int32)
    for y in range(rows):
        for x in range(cols):
            a = ang[row0 + y, x]
            a = a - pi if a >= pi else a
            a = a * scale
            a = a - half
            f = np.floor(a)
            a = a - f
            m = mag[row0 + y, x]
            w = m * a
            w_hi[y, x] = w
            w_lo[y, x] = m - w
            lo[y, x] = int(f)
    # 2. sums: per cell row, the row's cells side by side (each cell's order unchanged)
    lo_sum = np.empty((nx, bins))
    hi_sum = np.empty((nx, bins))
    for cy in range(ny):
        lo_sum[:] = 0.0
        hi_sum[:] = 0.0
        for y in range(cy * cell_px, (cy + 1) * cell_px):
            for dx in range(cell_px):
                for cx in range(nx):
                    x = cx * cell_px + dx
                    b = lo[y, x]
                    if b < 0:
                        b = bins - 1
                    lo_sum[cx, b] += np.float64(w_lo[y, x])
                    b += 1
                    if b == bins:
                        b = 0
                    hi_sum[cx, b] += np.float64(w_hi[y, x])
        for cx in range(nx):
            for b in range(bins):
                out[cy, cx, b] = lo_sum[cx, b] + hi_sum[cx, b]


@_jit  # type: ignore[misc]
def integral32(hist: np.ndarray, out: np.ndarray) -> None:
    """``out (ny + 1, nx + 1, bins)`` float32, first row and column zero: the float64 cumulative sums of
    ``hist (ny, nx, bins)`` down the rows, then along each row, rounded to float32."""
    ny, nx, bins = hist.shape
    col = np.empty((nx, bins))
    run = np.empty(bins)
    out[0, :, :] = 0.0
    for y in range(ny):
        out[y + 1, 0, :] = 0.0
        for x in range(nx):
            for b in range(bins):
                col[x, b] = hist[y, x, b] if y == 0 else col[x, b] + hist[y, x, b]
        for x in range(nx):
            for b in range(bins):
                run[b] = col[x, b] if x == 0 else run[b] + col[x, b]
                out[y + 1, x + 1, b] = np.float32(run[b])


@_jit  # type: ignore[misc]
def block_columns(rows: np.ndarray, width: np.ndarray, offset: np.ndarray, ox: np.ndarray, oy: np.ndarray,
                  unit_px: int, blocks: np.ndarray, col_block: np.ndarray, col_local: np.ndarray,
                  out: np.ndarray) -> None:
    """``hog_blocks.block_features_rows`` with ``columns``: column ``j`` of ``out (k, columns)`` is value
    ``col_local[j]`` of block ``col_block[j]``, with the numpy path's operations in its order."""
    bins = rows.shape[1]
    n = 4 * bins
    cells = np.empty(n, np.float32)
    acc = np.empty(8, np.float32)
    for w in range(ox.shape[0]):
        wide = width[w]
        for i in range(blocks.shape[0]):
            hw = blocks[i, 2] // 2 // unit_px
            hh = blocks[i, 3] // 2 // unit_px
            base = ((oy[w] + blocks[i, 1]) // unit_px) * wide + (ox[w] + blocks[i, 0]) // unit_px + offset[w]
            down = hh * wide
            for r in range(2):
                for c in range(2):
                    i00 = base + r * down + c * hw
                    i01 = i00 + hw
                    i10 = i00 + down
                    i11 = i10 + hw
                    for b in range(bins):
                        cells[(2 * r + c) * bins + b] = ((rows[i11, b] - rows[i01, b]) - rows[i10, b]) + rows[i00, b]
            for j in range(8):
                acc[j] = cells[j] * cells[j] + cells[j + 8] * cells[j + 8]
            for s in range(16, n - n % 8, 8):
                for j in range(8):
                    acc[j] += cells[s + j] * cells[s + j]
            total = (acc[0] + acc[1]) + (acc[2] + acc[3])
            total += (acc[4] + acc[5]) + (acc[6] + acc[7])
            for j in range(n - n % 8, n):
                total += cells[j] * cells[j]
            norm = np.sqrt(total) + np.float32(blocks[i, 2] * blocks[i, 3])
            for j in range(col_block.shape[0]):
                if col_block[j] == i:
                    out[w, j] = cells[col_local[j]] / norm


@_jit  # type: ignore[misc]
def grey(image: np.ndarray, out: np.ndarray) -> None:
    """``out (h, w)`` float32 = ``(0.114 B + 0.587 G) + 0.299 R`` of ``image (h, w, 3)`` uint8 BGR, as numpy does."""
    cb, cg, cr = np.float32(0.114), np.float32(0.587), np.float32(0.299)
    for y in range(image.shape[0]):
        for x in range(image.shape[1]):
            out[y, x] = (np.float32(image[y, x, 0]) * cb + np.float32(image[y, x, 1]) * cg) + \
                np.float32(image[y, x, 2]) * cr
