"""The fast HOG paths (banded cell histograms, strided first-stage features, planar grey) give bit for bit what
the plain ones give: the plain whole-image histograms and the gather-only cascade are kept here as oracles."""

from __future__ import annotations

import cv2
import numpy as np
import pytest

import lookalike.vision.hog_blocks as hb
import lookalike.vision.hog_cascade as hc
import lookalike.vision.hog_features as hf
from lookalike.vision.hog_features import BINS, as_bgr_image, cell_histograms, to_grey
from lookalike.vision.pipeline import shipped_model_path


def plain_gradient_bins(grey: np.ndarray, bins: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    g = np.asarray(grey, dtype=np.float32)
    gx = cv2.Sobel(g, cv2.CV_32F, 1, 0, ksize=1)
    gy = cv2.Sobel(g, cv2.CV_32F, 0, 1, ksize=1)
    gx[:, 0] = gx[:, -1] = 0.0
    gy[0, :] = gy[-1, :] = 0.0
    mag, ang = cv2.cartToPolar(gx, gy)
    ang -= np.float32(np.pi) * (ang >= np.pi)
    ang *= np.float32(bins / np.pi)
    ang -= np.float32(0.5)
    lo = np.floor(ang)
    w_hi = mag * (ang - lo)
    lo_i = lo.astype(np.int32)
    lo_i %= bins
    return lo_i, mag - w_hi, w_hi


def plain_cell_histograms(grey: np.ndarray, cell_px: int, bins: int = BINS) -> np.ndarray:
    g = np.asarray(grey, dtype=np.float32)
    ny, nx = g.shape[0] // cell_px, g.shape[1] // cell_px
    lo, w_lo, w_hi = (a[: ny * cell_px, : nx * cell_px] for a in plain_gradient_bins(g, bins))
    rows = (np.arange(ny * cell_px) // cell_px) * (nx * bins)
    cols = (np.arange(nx * cell_px) // cell_px) * bins
    base = rows[:, None] + cols[None, :]
    n = ny * nx * bins
    hist = np.bincount((base + lo).ravel(), w_lo.ravel(), n)
    hist += np.bincount((base + (lo + 1) % bins).ravel(), w_hi.ravel(), n)
    return hist.reshape(ny, nx, bins).transpose(2, 0, 1)


def plain_block_features_rows(rows: np.ndarray, width: int, blocks: np.ndarray, ox: np.ndarray,
                              oy: np.ndarray, unit_px: int) -> np.ndarray:
    """All block descriptors by row gathers, normalised with numpy's own sum over each block's 36 values."""
    k, d = len(ox), 4 * BINS
    bx, by, bw, bh = np.asarray(blocks, np.int64).T
    hw, hh = bw // 2 // unit_px, bh // 2 // unit_px
    base = ((oy[:, None] + by) // unit_px) * width + (ox[:, None] + bx) // unit_px
    step = np.arange(3)[:, None] * (hh * width)[:, None, None] + np.arange(3) * hw[:, None, None]
    c = rows[base[:, :, None, None] + step]
    cells = (c[:, :, 1:, 1:] - c[:, :, :-1, 1:] - c[:, :, 1:, :-1] + c[:, :, :-1, :-1]).reshape(k, len(bw), d)
    denom = np.sqrt((cells * cells).sum(axis=2, keepdims=True)) + (bw * bh).astype(cells.dtype)[:, None]
    return (cells / denom).reshape(k, -1)


def plain_windows(model: hc.HogCascade, image: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """HogCascade.windows with the plain histograms and gathers for every stage."""
    cfg = model.config
    img = np.asarray(image).astype(np.float32)
    grey = 0.114 * img[..., 0] + 0.587 * img[..., 1] + 0.299 * img[..., 2]
    win_w, win_h = cfg.window_px
    step = cfg.stride_cells * cfg.cell_px
    boxes, margins = [], []
    scale = win_h / cfg.min_height_px
    while win_h / scale <= cfg.max_height_px:
        size = (int(round(grey.shape[1] * scale)), int(round(grey.shape[0] * scale)))
        if size[0] < win_w or size[1] < win_h:
            break
        level = grey if size == (grey.shape[1], grey.shape[0]) else cv2.resize(
            grey, size, interpolation=cv2.INTER_AREA if scale < 1 else cv2.INTER_LINEAR)
        hist = plain_cell_histograms(level, cfg.cell_px).transpose(1, 2, 0)
        integral = np.zeros((hist.shape[0] + 1, hist.shape[1] + 1, BINS))
        np.cumsum(np.cumsum(hist, axis=0), axis=1, out=integral[1:, 1:])
        rows = integral.astype(np.float32).reshape(-1, BINS)
        ys, xs = np.mgrid[0 : size[1] - win_h + 1 : step, 0 : size[0] - win_w + 1 : step]
        ox, oy = xs.ravel(), ys.ravel()
        alive, margin = np.arange(len(ox)), np.zeros(0)
        for stage, (used, columns) in zip(model.stages, model._stage_blocks):
            if not len(alive):
                break
            cols = plain_block_features_rows(rows, integral.shape[1], used, ox[alive], oy[alive],
                                             cfg.cell_px)[:, columns]
            margin = np.where((cols > stage.threshold) == (stage.sign > 0), 1.0, -1.0) @ stage.weight
            keep = margin >= stage.bias
            alive, margin = alive[keep], margin[keep]
        if len(alive):
            boxes.append(np.column_stack([ox[alive] / scale, oy[alive] / scale, np.full(len(alive), win_w / scale),
                                          np.full(len(alive), win_h / scale)]))
            margins.append(margin)
        scale /= cfg.scale_step
    if not boxes:
        return np.zeros((0, 4)), np.zeros(0)
    return np.concatenate(boxes).astype(float), np.concatenate(margins)


@pytest.mark.parametrize("band_pixels", [1, 300, 1 << 15])
def test_banded_cell_histograms_equal_the_whole_image_ones(monkeypatch, band_pixels: int) -> None:
    monkeypatch.setattr(hf, "_BAND_PIXELS", band_pixels)
    rng = np.random.default_rng(0)
    for shape in ((37, 50), (64, 32), (9, 9), (101, 67), (480, 640)):
        g = rng.uniform(0, 255, shape).astype(np.float32)
        g[: shape[0] // 3] = 128.0  # flat rows: zero gradients, angle 0
        for cell in (3, 4, 8):
            if min(shape) >= cell:
                assert np.array_equal(cell_histograms(g, cell), plain_cell_histograms(g, cell)), (shape, cell)


@pytest.mark.parametrize("band_pixels", [1, 100, 1 << 15])
def test_grey_equals_the_plain_weighted_sum(monkeypatch, band_pixels: int) -> None:
    monkeypatch.setattr(hf, "_BAND_PIXELS", band_pixels)
    img = np.random.default_rng(1).integers(0, 256, (31, 47, 3)).astype(np.uint8)
    f = img.astype(np.float32)
    assert np.array_equal(to_grey(img), 0.114 * f[..., 0] + 0.587 * f[..., 1] + 0.299 * f[..., 2])


def test_strided_first_stage_features_equal_the_gathers() -> None:
    rng = np.random.default_rng(2)
    hist = rng.uniform(0, 50, (30, 40, BINS))
    integral = np.zeros((31, 41, BINS))
    integral[1:, 1:] = hist.cumsum(axis=0).cumsum(axis=1)
    blocks = hb.block_pool((32, 64), 4)[::7]
    ys, xs = np.mgrid[0 : 120 - 64 + 1 : 8, 0 : 160 - 32 + 1 : 8]
    rows = integral.astype(np.float32).reshape(-1, BINS)
    planes = np.ascontiguousarray(integral.transpose(2, 0, 1), dtype=np.float32)
    grid = hb.block_features_grid(planes, blocks, xs.shape, 2, 4)
    plain = plain_block_features_rows(rows, 41, blocks, xs.ravel(), ys.ravel(), 4)
    assert np.array_equal(grid, plain)
    assert np.array_equal(hb.block_features_rows(rows, 41, blocks, xs.ravel(), ys.ravel(), 4), plain)


def test_block_norms_equal_numpys_sum_over_wide_ranges() -> None:
    rng = np.random.default_rng(6)
    cells = (rng.standard_normal((2, 2, BINS, 50, 40)) * np.exp(rng.uniform(-10, 10, (2, 2, BINS, 50, 40))))
    cells = cells.astype(np.float32)
    cells[rng.random(cells.shape) < 0.3] = 0.0
    flat = np.ascontiguousarray(cells.transpose(3, 4, 0, 1, 2)).reshape(50, 40, 4 * BINS)
    expected = np.sqrt((flat * flat).sum(axis=2)) + np.float32(48)
    assert np.array_equal(hb._block_norms(cells, np.float32(48)), expected)


def test_stacked_integrals_equal_one_at_a_time() -> None:
    rng = np.random.default_rng(8)
    blocks = hb.block_pool((32, 64), 4)[::5]
    parts, stacked, ox, oy, width, offset = [], [], [], [], [], []
    first = 0
    for h, w in ((30, 40), (24, 31), (17, 20)):
        integral = np.zeros((h + 1, w + 1, BINS))
        integral[1:, 1:] = rng.uniform(0, 50, (h, w, BINS)).cumsum(axis=0).cumsum(axis=1)
        rows = integral.astype(np.float32).reshape(-1, BINS)
        ys, xs = np.mgrid[0 : 4 * h - 64 + 1 : 8, 0 : 4 * w - 32 + 1 : 8]
        parts.append(plain_block_features_rows(rows, w + 1, blocks, xs.ravel(), ys.ravel(), 4))
        stacked.append(rows)
        ox.append(xs.ravel())
        oy.append(ys.ravel())
        width.append(np.full(xs.size, w + 1))
        offset.append(np.full(xs.size, first))
        first += len(rows)
    got = hb.block_features_rows(np.concatenate(stacked), np.concatenate(width), blocks, np.concatenate(ox),
                                 np.concatenate(oy), 4, offset=np.concatenate(offset))
    assert np.array_equal(got, np.concatenate(parts))


def test_shipped_detector_windows_equal_the_plain_path() -> None:
    from lookalike.geometry.camera import Camera
    from lookalike.sim.render_robots import RobotRenderer

    model = hc.HogCascade.load(shipped_model_path("detector"))
    renderer = RobotRenderer(camera=Camera.default(640, 480), seed=7)
    rng = np.random.default_rng(7)
    images = [renderer.render(np.column_stack([d, rng.uniform(-0.5, 0.5, len(d)) * d]),
                              rng.uniform(-np.pi, np.pi, len(d))).image
              for d in (rng.uniform(1, 5, 4),)]
    images.append(rng.integers(0, 256, (240, 320, 3)).astype(np.uint8))
    found = 0
    for image in images:
        fast, plain = model.windows(image), plain_windows(model, as_bgr_image(image))
        assert np.array_equal(fast[0], plain[0]) and np.array_equal(fast[1], plain[1])
        found += len(fast[0])
    assert found > 0


def test_row_by_row_cumsum_equals_numpy() -> None:
    a = np.random.default_rng(4).uniform(0, 1e4, (37, 11, BINS))
    assert np.array_equal(hb.cumsum_rows(a), np.cumsum(a, axis=0))
    assert hb.cumsum_rows(np.zeros((0, 3))).shape == (0, 3)


def test_selected_columns_equal_the_full_features() -> None:
    rng = np.random.default_rng(5)
    integral = np.zeros((31, 41, BINS))
    integral[1:, 1:] = rng.uniform(0, 50, (30, 40, BINS)).cumsum(axis=0).cumsum(axis=1)
    blocks = hb.block_pool((32, 64), 4)[::9]
    columns = rng.choice(len(blocks) * 4 * BINS, 17, replace=False)
    ys, xs = np.mgrid[0 : 120 - 64 + 1 : 8, 0 : 160 - 32 + 1 : 8]
    rows = integral.astype(np.float32).reshape(-1, BINS)
    planes = np.ascontiguousarray(integral.transpose(2, 0, 1), dtype=np.float32)
    full = plain_block_features_rows(rows, 41, blocks, xs.ravel(), ys.ravel(), 4)
    assert np.array_equal(hb.block_features_rows(rows, 41, blocks, xs.ravel(), ys.ravel(), 4), full)
    assert np.array_equal(hb.block_features_rows(rows, 41, blocks, xs.ravel(), ys.ravel(), 4, columns),
                          full[:, columns])
    assert np.array_equal(hb.block_features_grid(planes, blocks, xs.shape, 2, 4, columns), full[:, columns])
