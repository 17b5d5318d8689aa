"""The compiled HOG kernels (numba, optional) give bit for bit what the numpy path gives: cell histograms, their
float32 integral and the shipped detector's windows and margins."""

from __future__ import annotations

from collections.abc import Iterator

import cv2
import numpy as np
import pytest

import lookalike.vision.hog_features as hf
import lookalike.vision.hog_kernels as hk
from lookalike.vision.hog_blocks import cell_integral32
from lookalike.vision.hog_cascade import HogCascade
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
