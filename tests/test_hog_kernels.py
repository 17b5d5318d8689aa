"""The compiled HOG kernels (numba, optional) give bit for bit what the numpy path gives: cell histograms, their
float32 integral and the shipped detector's windows and margins."""

from __future__ import annotations

from collections.abc import Iterator

import cv2
import numpy as np
import pytest

import lookalike.vision.hog_features as hf
import lookalike.vision.hog_kernels as hk
from lookalike.vision.hog_blocks import block_features_grid, block_features_rows, block_pool, cell_integral32
from lookalike.vision.hog_cascade import HogCascade
from lookalike.vision.hog_features import BINS
from lookalike.vision.pipeline import shipped_model_path

numba = pytest.importorskip("numba", reason="numba (the `fast` extra) is not installed: only the numpy path runs")


@pytest.fixture(autouse=True)
def _default_switch() -> Iterator[None]:
    yield
    hk.use_compiled(None)


def both(fn, *args):  # type: ignore[no-untyped-def]
    hk.use_compiled(True)
    assert hk.compiled() is not None
    fast = fn(*args)
    hk.use_compiled(False)
    assert hk.compiled() is None
    return fast, fn(*args)


def awkward_greys() -> Iterator[np.ndarray]:
    rng = np.random.default_rng(11)
    for shape in ((9, 9), (37, 50), (64, 32), (101, 67), (480, 640)):
        yield rng.uniform(0, 255, shape).astype(np.float32)
        steps = rng.integers(0, 4, shape).astype(np.float32) * np.float32(0.299)  # many exact 0 and 180 degrees
        steps[:, : shape[1] // 2] = 128.0  # flat: zero gradients
        yield steps
        yield cv2.GaussianBlur(rng.uniform(0, 255, shape).astype(np.float32), (0, 0), 2.0)  # tiny gradients
        tiny = np.float32(100) + rng.integers(0, 2, shape).astype(np.float32) * np.float32(7.6e-6)
        yield tiny  # gradients of one float32 step beside large grey values


@pytest.mark.parametrize("band_pixels", [1, 500, 1 << 15])
def test_compiled_cell_histograms_equal_numpys(monkeypatch, band_pixels: int) -> None:
    monkeypatch.setattr(hf, "_BAND_PIXELS", band_pixels)
    for grey in awkward_greys():
        for cell in (3, 4, 8):
            if min(grey.shape) >= cell:
                fast, plain = both(hf.cell_histograms, grey, cell)
                assert fast.dtype == plain.dtype == np.float64
                assert np.array_equal(fast, plain), (grey.shape, cell)


def test_compiled_integral_equals_numpys() -> None:
    rng = np.random.default_rng(12)
    for shape in ((1, 1, 9), (5, 7, 9), (120, 160, 9)):
        hist = rng.uniform(0, 300, shape) * np.exp(rng.uniform(-20, 5, shape))
        hist[rng.random(shape) < 0.3] = 0.0
        fast, plain = both(cell_integral32, hist)
        assert fast.dtype == plain.dtype == np.float32
        assert np.array_equal(fast, plain)
        assert not fast[0].any() and not fast[:, 0].any()


def test_compiled_block_columns_equal_numpys() -> None:
    rng = np.random.default_rng(13)
    blocks = block_pool((32, 64), 4)
    stacked, ox, oy, width, offset, first = [], [], [], [], [], 0
    for h, w in ((30, 40), (17, 20)):
        hist = rng.uniform(0, 50, (h, w, BINS)) * np.exp(rng.uniform(-8, 3, (h, w, BINS)))
        hist[rng.random(hist.shape) < 0.2] = 0.0
        hist[: h // 3] = 0.0  # flat: zero blocks, norm = area
        rows = cell_integral32(hist)
        ys, xs = np.mgrid[0 : 4 * h - 64 + 1 : 8, 0 : 4 * w - 32 + 1 : 8]
        columns = rng.choice(len(blocks) * 4 * BINS, 25, replace=False)
        planes = np.ascontiguousarray(rows.transpose(2, 0, 1))
        grid = block_features_grid(planes, blocks, xs.shape, 2, 4, columns)  # numpy only
        fast, plain = both(block_features_rows, rows.reshape(-1, BINS), w + 1, blocks, xs.ravel(), ys.ravel(), 4,
                           columns)
        assert np.array_equal(fast, plain) and np.array_equal(fast, grid)
        assert fast.flags.f_contiguous and plain.flags.f_contiguous
        stacked.append(rows.reshape(-1, BINS))
        ox.append(xs.ravel())
        oy.append(ys.ravel())
        width.append(np.full(xs.size, w + 1))
        offset.append(np.full(xs.size, first))
        first += len(stacked[-1])
    args = (np.concatenate(stacked), np.concatenate(width), blocks[::3], np.concatenate(ox), np.concatenate(oy), 4)
    columns = rng.choice(len(blocks[::3]) * 4 * BINS, 40, replace=False)
    fast, plain = both(block_features_rows, *args, columns, np.concatenate(offset))
    assert np.array_equal(fast, plain)


def test_shipped_detector_is_the_same_with_and_without_the_kernels() -> None:
    from lookalike.geometry.camera import Camera
    from lookalike.sim.render_robots import RobotRenderer

    model = HogCascade.load(shipped_model_path("detector"))
    renderer = RobotRenderer(camera=Camera.default(640, 480), seed=21)
    rng = np.random.default_rng(21)
    depth = rng.uniform(1, 5, 3)
    images = [renderer.render(np.column_stack([depth, rng.uniform(-0.5, 0.5, 3) * depth]),
                              rng.uniform(-np.pi, np.pi, 3)).image,
              rng.integers(0, 256, (200, 150, 3)).astype(np.uint8)]
    found = 0
    for image in images:
        (fb, fm), (pb, pm) = both(model.windows, image)
        assert np.array_equal(fb, pb) and np.array_equal(fm, pm)
        found += len(fb)
    assert found > 0


def test_the_switch_and_the_environment_variable(monkeypatch) -> None:
    hk.use_compiled(None)
    monkeypatch.setenv("LOOKALIKE_HOG_NUMBA", "0")
    assert hk.compiled() is None
    monkeypatch.delenv("LOOKALIKE_HOG_NUMBA")
    assert hk.compiled() is not None
    hk.use_compiled(False)
    assert hk.compiled() is None
