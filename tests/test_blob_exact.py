"""The blob detector's and the settings estimate's OpenCV steps give exactly what the plain numpy formulas give."""

import itertools

import cv2
import numpy as np
import pytest

from lookalike.vision.blob import BlobConfig, BlobDetector, median_frame, spread
from lookalike.vision.blob_auto import _dark_bright, _radii
from lookalike.vision.blob_shape import blob_shapes


def _frames(n: int, seed: int = 0) -> list[np.ndarray]:
    """Dark and bright discs and small specks moving over a textured background (uint8 BGR, 90x120)."""
    rng = np.random.default_rng(seed)
    bg = rng.integers(90, 170, (90, 120, 3)).astype(float)
    yy, xx = np.mgrid[:90, :120]
    frames = []
    for t in range(n):
        img = bg.copy()
        for k, (cx, cy, value) in enumerate([(10 + 3 * t, 30, 20), (100 - 2 * t, 60, 240), (60, 10 + 2 * t, 60)]):
            img[(xx - cx) ** 2 + (yy - cy) ** 2 <= 25 + 10 * k] = (value, value - k * 10, value + k * 5)
        img[rng.integers(0, 90, 20), rng.integers(0, 120, 20)] = rng.integers(0, 256, (20, 3))
        frames.append(img.clip(0, 255).astype(np.uint8))
    return frames


def _reference(cfg: BlobConfig, fit: list[np.ndarray], image: np.ndarray):
    """Mask, difference and detections as the plain numpy formulas give them (median method, fitted)."""
    def prepare(im):
        return (cv2.GaussianBlur(im, (cfg.blur_px,) * 2, 0) if cfg.blur_px > 1 else im).astype(np.float32)

    background = np.median(np.stack([prepare(fit[i]) for i in spread(len(fit), cfg.history)]), axis=0)
    d = prepare(image) - background.astype(np.float32)
    b, g, r = d[..., 0], d[..., 1], d[..., 2]
    diff = {"dark": lambda: np.maximum(-np.minimum(np.minimum(b, g), r), 0),
            "bright": lambda: np.maximum(np.maximum(np.maximum(b, g), r), 0),
            "any": lambda: np.maximum(np.maximum(np.abs(b), np.abs(g)), np.abs(r))}[cfg.polarity]()
    mask = np.where(diff > cfg.threshold, 255, 0).astype(np.uint8)
    for op, size in ((cv2.MORPH_OPEN, cfg.open_px), (cv2.MORPH_CLOSE, cfg.close_px)):
        if size > 1:
            mask = cv2.morphologyEx(mask, op, cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (size, size)))
    count, labels, stats, _ = cv2.connectedComponentsWithStats(mask, connectivity=8)
    keep = [k for k in range(1, count) if cfg.min_area_px <= stats[k, 4] <= cfg.max_area_px]
    return mask, diff, stats[keep, :4].astype(float), blob_shapes(labels, stats, keep, diff, image)


@pytest.mark.parametrize("polarity", ["dark", "bright", "any"])
@pytest.mark.parametrize(("threshold", "blur_px", "history"), [(30.0, 5, 25), (17.3, 0, 6), (61.7, 3, 7)])
def test_detector_gives_the_numpy_formulas_rows(polarity: str, threshold: float, blur_px: int, history: int) -> None:
    frames = _frames(12)
    cfg = BlobConfig(polarity=polarity, threshold=threshold, blur_px=blur_px, history=history, min_area_px=10,
                     open_px=3, close_px=5)
    det = BlobDetector(cfg, describe=True).fit(frames)
    for image in frames[::3]:
        mask, diff, boxes, shapes = _reference(cfg, frames, image)
        got_mask, got_diff = det.foreground(image)
        np.testing.assert_array_equal(got_mask, mask)
        np.testing.assert_array_equal(got_diff, diff)
        found = det(image)
        assert len(found) == len(boxes) > 0
        np.testing.assert_array_equal(found.xywh, boxes)
        np.testing.assert_array_equal(found.feature, shapes)


def test_estimate_steps_give_the_numpy_formulas() -> None:
    stack = np.stack(_frames(7)).astype(np.float32)
    background = np.median(stack, axis=0)
    diff = stack - background
    dark, bright = _dark_bright(stack, background)
    for got, want in zip(_dark_bright(np.stack(_frames(7)), background), (dark, bright)):  # uint8 frames: the same
        np.testing.assert_array_equal(got, want)
    np.testing.assert_array_equal(dark, np.maximum(-diff.min(axis=3), 0))
    np.testing.assert_array_equal(bright, np.maximum(diff.max(axis=3), 0))
    np.testing.assert_array_equal(np.median(np.stack(_frames(7)), axis=0).astype(np.float32), background)
    masks = [cv2.compare(d, 25.0, cv2.CMP_GT) for d in dark]
    for mask, sig in zip(masks, dark):
        np.testing.assert_array_equal(mask, np.where(sig > 25.0, 255, 0).astype(np.uint8))
    radii = []
    for mask in masks:  # the largest inscribed radius per component, over every pixel
        _, labels = cv2.connectedComponents(mask, connectivity=8)
        dist = cv2.distanceTransform(mask, cv2.DIST_L2, 3)
        peak = np.zeros(labels.max() + 1)
        np.maximum.at(peak, labels.ravel(), dist.ravel())
        sizes = np.bincount(labels.ravel())
        radii.extend(peak[1:][(sizes[1:] >= 20 / 5) & (sizes[1:] <= 20 * 6)].tolist())
    assert _radii(masks, 20.0) == radii


@pytest.mark.parametrize("polarity", ["dark", "bright", "any"])
def test_the_band_of_background_grey_levels_is_the_float32_comparison(polarity: str) -> None:
    rng = np.random.default_rng(1)
    values = [rng.integers(0, 256, 300), rng.integers(0, 511, 300) / 2, rng.uniform(0, 255, 297), [0, 255, 127.5]]
    background = np.concatenate(values).astype(np.float32).reshape(30, 10, 3)
    for threshold in (0.3, 1.0, 17.3, 30.0, 61.7, 200.5, 254.9):
        det = BlobDetector(BlobConfig(polarity=polarity, threshold=threshold))
        det.background_, det._fitted = background, True
        lower, upper = det._band()
        for v in range(256):
            d = np.float32(v) - background  # as _difference: the frame minus the background, in float32
            darker, brighter = -d > threshold, d > threshold
            outside = {"dark": darker, "bright": brighter, "any": darker | brighter}[polarity]
            np.testing.assert_array_equal((v < lower) | (v > upper), outside)


def test_the_median_frame_is_numpys_median() -> None:
    rng = np.random.default_rng(2)
    for n in range(1, 32):
        for stack in (rng.integers(0, 4, (n, 20, 9)).astype(np.uint8), rng.integers(0, 256, (n, 5, 3)).astype(np.uint8),
                      rng.normal(100, 50, (n, 6, 4)).astype(np.float32)) + (
                          (rng.integers(0, 256, (n, 130, 70, 3)).astype(np.uint8),) if n in (3, 25) else ()):  # blocks
            np.testing.assert_array_equal(median_frame(stack), np.median(stack, axis=0).astype(np.float32))
    for n in range(1, 14, 2):  # every 0/1 input (the 0-1 principle: the network then finds the middle of any input)
        bits = np.array(list(itertools.product([0, 1], repeat=n)), np.uint8).T
        np.testing.assert_array_equal(median_frame(bits), np.median(bits, axis=0).astype(np.float32))


def test_shape_means_are_numpys_means() -> None:
    rng = np.random.default_rng(3)
    mask = (cv2.GaussianBlur(rng.uniform(0, 1, (80, 90)), (9, 9), 0) > 0.52).astype(np.uint8)
    count, labels, stats, _ = cv2.connectedComponentsWithStats(mask, connectivity=8)
    difference = rng.uniform(0, 90, mask.shape).astype(np.float32)
    image = rng.integers(0, 256, (*mask.shape, 3)).astype(np.uint8)
    keep = list(range(1, count))
    shapes = blob_shapes(labels, stats, keep, difference, image)
    assert len(keep) > 3
    for k, row in zip(keep, shapes):
        inside = labels == k
        assert row[3] == np.mean(difference[inside].astype(float))  # mean darkness
        np.testing.assert_array_equal(row[4:7], image[inside].astype(float).mean(axis=0))  # mean B, G, R
