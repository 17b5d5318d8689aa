"""Background-subtraction blob detector for static cameras: foreground differs from a ``median`` (or ``mog2``)
background by more than ``threshold`` grey levels; after opening and closing, each component of ``min_area_px`` to
``max_area_px`` becomes a box scoring 1 (docs/blobs.md)."""

from __future__ import annotations

import hashlib
import math
from collections import deque
from collections.abc import Iterable
from dataclasses import dataclass, field
from functools import lru_cache
from pathlib import Path
from typing import Any

import numpy as np

from lookalike._optional import needs
from lookalike.types import Detections
from lookalike.vision.hog_features import as_bgr_image

SOURCE_HASH = hashlib.sha256(Path(__file__).read_bytes()).hexdigest()
"""SHA-256 of this module's source as imported (cache keys name the code that runs, not the file on disk)."""

_METHODS = ("median", "mog2")
_POLARITIES = ("any", "dark", "bright")


def spread(n: int, count: int) -> np.ndarray:
    """Up to ``count`` indices spread evenly over ``range(n)``, increasing."""
    return np.unique(np.linspace(0, n - 1, min(n, count)).round().astype(int))


def median_frame(stack: np.ndarray) -> np.ndarray:
    """``np.median(stack, axis=0)`` as float32, for ``(n, ...)`` uint8 or float32 frames without NaN. Of an odd number
    of frames, the middle value of a sorting network of elementwise minima and maxima, run on blocks of pixels small
    enough to stay in the CPU's cache: the same value as numpy's per-pixel selection, several times faster."""
    n = len(stack)
    if n % 2 == 0 or stack.dtype not in (np.uint8, np.float32):
        return np.median(stack, axis=0).astype(np.float32)
    flat = stack.reshape(n, -1)
    out = np.empty(flat.shape[1], stack.dtype)
    buffer = np.empty((n + 1, _MEDIAN_BLOCK), stack.dtype)
    for start in range(0, flat.shape[1], _MEDIAN_BLOCK):
        size = min(_MEDIAN_BLOCK, flat.shape[1] - start)
        rows = list(buffer[:, :size])
        for row, frame in zip(rows, flat[:, start:start + size]):
            row[...] = frame
        spare = rows.pop()
        for i, j in _median_network(n):
            np.minimum(rows[i], rows[j], out=spare)
            np.maximum(rows[i], rows[j], out=rows[j])
            rows[i], spare = spare, rows[i]
        out[start:start + size] = rows[n // 2]
    return out.reshape(stack.shape[1:]).astype(np.float32, copy=False)


_MEDIAN_BLOCK = 16384  # pixel values per block of median_frame


@lru_cache(maxsize=8)
def _median_network(n: int) -> tuple[tuple[int, int], ...]:
    """The comparators ``(i, j)``, ``i < j``, of Batcher's odd-even merge sort of ``n`` values (the smaller value goes
    to ``i``) that the middle position ``n // 2`` depends on, in order."""
    pairs = []
    p = 1
    while p < n:  # merge sorted runs of p into runs of 2p
        k = p
        while k >= 1:
            for j in range(k % p, n - k, 2 * k):
                pairs += [(i + j, i + j + k) for i in range(min(k, n - j - k))
                          if (i + j) // (2 * p) == (i + j + k) // (2 * p)]
            k //= 2
        p *= 2
    needed, kept = {n // 2}, []
    for i, j in reversed(pairs):
        if i in needed or j in needed:
            kept.append((i, j))
            needed |= {i, j}
    return tuple(reversed(kept))


@dataclass(frozen=True)
class BlobConfig:
    """Blob detector settings; sizes in pixels of the input image, differences in grey levels (0..255)."""

    method: str = "median"
    threshold: float = 30.0
    polarity: str = "any"  # "dark": objects darker than the background (zebrafish), "bright", or both
    min_area_px: float = 80.0
    max_area_px: float = math.inf
    blur_px: int = 5  # Gaussian blur kernel (odd; 0 or 1 disables)
    open_px: int = 3
    close_px: int = 9
    history: int = 25  # frames in the median (sampled across the video by fit) or MOG2 history
    sample_every: int = 5  # rolling median without fit: keep every k-th frame
    stabilise: bool = False  # undo camera shake: shift each frame onto the first (phase correlation)

    def __post_init__(self) -> None:
        if self.method not in _METHODS:
            raise ValueError(f"BlobConfig.method: expected one of {_METHODS}, got {self.method!r}")
        if self.polarity not in _POLARITIES:
            raise ValueError(f"BlobConfig.polarity: expected one of {_POLARITIES}, got {self.polarity!r}")
        if not 0 < self.threshold < 255:
            raise ValueError(f"BlobConfig.threshold: must be in (0, 255), got {self.threshold!r}")
        if not 0 <= self.min_area_px <= self.max_area_px:
            raise ValueError(
                f"BlobConfig.min_area_px/max_area_px: need 0 <= min <= max, got {self.min_area_px}, {self.max_area_px}"
            )
        for name in ("blur_px", "open_px", "close_px"):
            if int(getattr(self, name)) < 0:
                raise ValueError(f"BlobConfig.{name}: must be >= 0, got {getattr(self, name)!r}")
        if self.blur_px > 1 and self.blur_px % 2 == 0:
            raise ValueError(f"BlobConfig.blur_px: must be odd, got {self.blur_px}")
        for name in ("history", "sample_every"):
            if int(getattr(self, name)) < 1:
                raise ValueError(f"BlobConfig.{name}: must be >= 1, got {getattr(self, name)!r}")


@dataclass
class BlobDetector:
    """Detects moving blobs in ``(h, w, 3)`` BGR frames of one static camera; one instance per video."""

    config: BlobConfig = field(default_factory=BlobConfig)
    describe: bool = False  # each box's feature: its blob's shape vector; parts_: the last frame's parts (blob_shape)
    split: bool = True  # with describe: parts_ of the large blobs (False: all NaN, cheaper where none is read)
    background_: np.ndarray | None = field(default=None, init=False, repr=False)
    parts_: np.ndarray | None = field(default=None, init=False, repr=False)
    _buffer: deque = field(init=False, repr=False)
    _seen: int = field(default=0, init=False, repr=False)
    _mog: Any = field(default=None, init=False, repr=False)
    _fitted: bool = field(default=False, init=False, repr=False)
    _reference: np.ndarray | None = field(default=None, init=False, repr=False)
    _window: np.ndarray | None = field(default=None, init=False, repr=False)
    _scratch: np.ndarray | None = field(default=None, init=False, repr=False)  # the 3-channel difference
    _bounds: tuple[np.ndarray, np.ndarray] | None = field(default=None, init=False, repr=False)  # see _band
    _boxes_difference: np.ndarray | None = field(default=None, init=False, repr=False)
    _areas: deque = field(init=False, repr=False)  # the recent blobs' areas (px²), for the parts' gate

    def __post_init__(self) -> None:
        from lookalike.vision.blob_shape import PART_WINDOW

        self._buffer = deque(maxlen=self.config.history)
        self._areas = deque(maxlen=PART_WINDOW)

    def reset(self) -> None:
        """Forget the background model."""
        self.background_ = None
        self._buffer.clear()
        self._seen = 0
        self._mog = None
        self._fitted = False
        self._reference = None
        self._window = None
        self._bounds = None
        self._areas.clear()

    def fit(self, frames: Iterable[np.ndarray] | np.ndarray) -> BlobDetector:
        """Median background of at most ``history`` of ``frames``, spread evenly (``median`` method only)."""
        if self.config.method != "median":
            raise ValueError("BlobDetector.fit: only the 'median' method has a fitted background")
        frames = list(frames)
        if not frames:
            raise ValueError("frames: no frames to fit a background on")
        stack = np.stack([self._prepare(frames[i], f"frames[{i}]") for i in spread(len(frames), self.config.history)])
        self.background_ = median_frame(stack)
        self._fitted, self._bounds = True, None
        return self

    def foreground(self, image: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``(mask, difference)``: ``(h, w)`` uint8 foreground (255) and float32 difference from the background."""
        mask, diff, _ = self._foreground(image, whole=True)
        assert diff is not None
        return mask, diff

    def _foreground(self, image: np.ndarray, whole: bool) -> tuple[np.ndarray, np.ndarray | None, np.ndarray]:
        """:meth:`foreground`'s mask, its difference (None when not ``whole`` and not needed for the mask) and the
        prepared frame."""
        with needs("cv2"):
            import cv2

        cfg = self.config
        img = self._prepare(image, "image")
        diff = None
        if cfg.method == "mog2":
            if self._mog is None:
                self._mog = cv2.createBackgroundSubtractorMOG2(
                    history=cfg.history, varThreshold=(cfg.threshold / 2.5) ** 2, detectShadows=False
                )
            raw = self._mog.apply(img.astype(np.uint8))
            bg = self._mog.getBackgroundImage()
            diff = self._difference(img, bg.astype(np.float32) if bg is not None else img.astype(np.float32))
            mask: np.ndarray = np.where((raw > 0) & (diff > 0), 255, 0).astype(np.uint8)
        else:
            if not self._fitted:
                if self._seen % cfg.sample_every == 0:
                    self._buffer.append(np.array(img))  # (a copy: img may be the caller's frame)
                    self.background_ = median_frame(np.stack(self._buffer))
                self._seen += 1
            if self.background_ is None or self.background_.shape != img.shape:
                raise ValueError(
                    f"image: shape {img.shape[:2]} differs from the background's "
                    f"{None if self.background_ is None else self.background_.shape[:2]}"
                )
            if whole or not self._fitted or img.dtype != np.uint8:
                diff = self._difference(img, self.background_)
                mask = cv2.compare(diff, np.array([cfg.threshold]), cv2.CMP_GT)  # 255 where diff > threshold
            else:  # the same mask from the frame's grey levels, without the difference image
                mask = cv2.bitwise_not(cv2.inRange(img, *self._band()))
        for op, size in ((cv2.MORPH_OPEN, cfg.open_px), (cv2.MORPH_CLOSE, cfg.close_px)):
            if size > 1:
                mask = cv2.morphologyEx(mask, op, cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (size, size)))
        return mask, diff, img

    def _band(self) -> tuple[np.ndarray, np.ndarray]:
        """``(lower, upper)``: ``(h, w, 3)`` uint8 grey levels, per pixel and channel, between which a uint8 frame is
        background: ``v`` is foreground when ``float32(background - v) > threshold`` (darker; polarity dark or any)
        or ``float32(v - background) > threshold`` (brighter; bright or any), as :meth:`_difference` compares it."""
        if self._bounds is None:
            assert self.background_ is not None
            bg, t = self.background_, np.float32(self.config.threshold)
            low = np.clip(np.ceil(bg.astype(float) - float(t)), 0, 255).astype(np.float32)  # darker: v < low
            high = np.clip(np.floor(bg.astype(float) + float(t)), 0, 255).astype(np.float32)  # brighter: v > high
            for _ in range(2):  # (float32 rounding moves an edge by at most one grey level)
                low += (low < 255) & (bg - low > t)
                low -= (low > 0) & ~(bg - (low - 1) > t)
                high -= (high > 0) & (high - bg > t)
                high += (high < 255) & ~(high + 1 - bg > t)
            polarity = self.config.polarity
            self._bounds = (low.astype(np.uint8) if polarity != "bright" else np.zeros(bg.shape, np.uint8),
                            high.astype(np.uint8) if polarity != "dark" else np.full(bg.shape, 255, np.uint8))
        return self._bounds

    def __call__(self, image: np.ndarray) -> Detections:
        """Detections of one frame: boxes ``xywh`` (px) of the blobs, each scoring 1 (with ``describe``, each blob's
        :func:`~lookalike.vision.blob_shape.blob_shapes` vector as its feature, and its
        :func:`~lookalike.vision.blob_shape.blob_part_vectors` vector as a row of ``parts_``)."""
        with needs("cv2"):
            import cv2

        cfg = self.config
        self.parts_ = None
        mask, difference, img = self._foreground(image, whole=False)
        # (BBDT: the labels and stats of the default algorithm, in the same order, faster)
        count, labels, stats, _ = cv2.connectedComponentsWithStatsWithAlgorithm(mask, 8, cv2.CV_32S, cv2.CCL_BBDT)
        keep = [k for k in range(1, count) if cfg.min_area_px <= stats[k, 4] <= cfg.max_area_px]
        if not keep:
            return Detections.empty()
        boxes = stats[keep, :4].astype(float)
        if not self.describe:
            return Detections(xywh=boxes, score=np.ones(len(keep)))
        from lookalike.vision.blob_shape import PART_SIZE, blob_part_vectors, blob_shapes

        if difference is None:  # the difference where the kept blobs lie (elsewhere, left from earlier frames)
            assert self.background_ is not None
            if self._boxes_difference is None or self._boxes_difference.shape != mask.shape:
                self._boxes_difference = np.zeros(mask.shape, np.float32)
            difference = self._boxes_difference
            for x, y, w, h in stats[keep, :4]:
                difference[y:y + h, x:x + w] = self._difference(img[y:y + h, x:x + w],
                                                                self.background_[y:y + h, x:x + w])
        shapes = blob_shapes(labels, stats, keep, difference, as_bgr_image(image, "image"))
        self._areas.extend(stats[keep, 4].tolist())
        self.parts_ = blob_part_vectors(labels, stats, keep, float(np.median(self._areas))) if self.split \
            else np.full((len(keep), PART_SIZE), np.nan)
        return Detections(xywh=boxes, score=np.ones(len(keep)), feature=shapes)

    detect = __call__

    def _prepare(self, image: np.ndarray, name: str) -> np.ndarray:
        """``image`` as blurred uint8 BGR (float32, shifted onto the first frame, when stabilising)."""
        with needs("cv2"):
            import cv2

        img = as_bgr_image(image, name)
        if self.config.blur_px > 1:
            img = cv2.GaussianBlur(img, (self.config.blur_px,) * 2, 0)
        return self._stabilise(img.astype(np.float32)) if self.config.stabilise else img

    def _stabilise(self, img: np.ndarray) -> np.ndarray:
        """Shift ``img`` (float32 BGR) by the translation that best aligns it with the first frame seen."""
        with needs("cv2"):
            import cv2

        grey = (img[..., 0] + img[..., 1] + img[..., 2]) / 3  # the channel mean, without a slow last-axis reduce
        if self._reference is None or self._reference.shape != grey.shape:
            self._reference = grey.astype(np.float32)
            self._window = cv2.createHanningWindow(grey.shape[::-1], cv2.CV_32F)
            return img
        (dx, dy), _ = cv2.phaseCorrelate(self._reference, grey.astype(np.float32), self._window)
        shift = np.array([[1, 0, -dx], [0, 1, -dy]], dtype=np.float32)
        return cv2.warpAffine(img, shift, grey.shape[::-1], borderMode=cv2.BORDER_REPLICATE)

    def _difference(self, img: np.ndarray, background: np.ndarray) -> np.ndarray:
        """``(h, w)`` float32 difference of ``img`` (uint8 or float32 BGR) from the float32 ``background`` by polarity:
        the most darkened channel, the most brightened or the largest change (grey levels, >= 0)."""
        with needs("cv2"):
            import cv2

        if self._scratch is None or self._scratch.shape != background.shape:
            self._scratch = np.empty(background.shape, np.float32)
        d = cv2.subtract(img, background, dst=self._scratch, dtype=cv2.CV_32F)  # img - background, kept between frames
        b, g, r = d[..., 0], d[..., 1], d[..., 2]
        if self.config.polarity == "dark":  # max(-min(b, g, r), 0)
            out = np.minimum(b, g)
            np.minimum(out, r, out=out)
            np.negative(out, out=out)
            return np.maximum(out, 0, out=out)
        if self.config.polarity == "any":  # max(|b|, |g|, |r|)
            np.abs(d, out=d)
        out = np.maximum(b, g)
        np.maximum(out, r, out=out)
        return out if self.config.polarity == "any" else np.maximum(out, 0, out=out)  # bright: max(b, g, r, 0)
