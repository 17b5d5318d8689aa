"""Hand-crafted appearance features of ``crop_px`` square crops: colour (25), frequency (6), edges and contour (12),
convex hull (5) and Hu moment (7) blocks of the foreground (what differs from the crop's border), standardised,
weighted per block and L2-normalised (``1 - f·g`` is the cosine distance)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol, runtime_checkable

import numpy as np

from lookalike._optional import needs

BLOCKS: tuple[tuple[str, int], ...] = (
    ("colour", 25),
    ("frequency", 6),
    ("edges", 12),
    ("hull", 5),
    ("hu", 7),
)
RAW_DIM = sum(size for _, size in BLOCKS)
_HU_FLOOR = 1e-9  # Hu values below this count as zero in the log scale


@runtime_checkable
class FeatureExtractor(Protocol):
    """Anything that turns the boxes of one image into appearance vectors (e.g. a re-ID network)."""

    dim: int

    def __call__(self, image: np.ndarray, xywh: np.ndarray) -> np.ndarray:
        """``(n, dim)`` L2-normalised features for boxes ``xywh (n, 4)`` (pixels) of ``image (h, w, 3)`` BGR uint8."""
        ...


@dataclass(frozen=True)
class FeatureStats:
    """Standardisation ``weight · (raw - mean) / scale``, all ``(RAW_DIM,)``; ``weight`` defaults to equal blocks."""

    mean: np.ndarray
    scale: np.ndarray
    weight: np.ndarray | None = None

    def __post_init__(self) -> None:
        if self.weight is None:
            object.__setattr__(self, "weight", _block_weights())
        for name in ("mean", "scale", "weight"):
            arr = np.asarray(getattr(self, name), dtype=float)
            if arr.shape != (RAW_DIM,) or not np.isfinite(arr).all():
                raise ValueError(f"FeatureStats.{name}: expected {RAW_DIM} finite values, got shape {arr.shape}")
            object.__setattr__(self, name, arr)
        if (self.scale <= 0).any():
            raise ValueError("FeatureStats.scale: every value must be positive")
        if (np.asarray(self.weight) < 0).any():
            raise ValueError("FeatureStats.weight: every value must be >= 0")


def _block_weights() -> np.ndarray:
    return np.concatenate([np.full(size, 1.0 / np.sqrt(size)) for _, size in BLOCKS])


def fit_stats(raw: np.ndarray, labels: np.ndarray | None = None, floor: float = 1e-3,
              max_weight: float = 3.0) -> FeatureStats:
    """Standardisation statistics of raw vectors ``(m, RAW_DIM)``: mean and spread, or with identity ``labels (m,)``
    the within-identity spread and weights ``sqrt(between / within)`` (at most ``max_weight``)."""
    raw = np.asarray(raw, dtype=float)
    if raw.ndim != 2 or raw.shape[1] != RAW_DIM or len(raw) < 2:
        raise ValueError(f"raw: expected shape (m >= 2, {RAW_DIM}), got {raw.shape}")
    mean = raw.mean(axis=0)
    if labels is None:
        spread = raw.std(axis=0)
    else:
        labels = np.asarray(labels)
        if labels.shape != (len(raw),):
            raise ValueError(f"labels: expected shape ({len(raw)},), got {labels.shape}")
        resid = raw.copy()
        for lab in np.unique(labels):
            rows = labels == lab
            resid[rows] -= raw[rows].mean(axis=0)
        spread = np.sqrt((resid**2).mean(axis=0))
    total = raw.std(axis=0)
    scale = np.maximum(spread, floor * np.maximum(total, 1.0))
    if labels is None:
        return FeatureStats(mean=mean, scale=scale)
    between = np.maximum(total**2 - spread**2, 0.0)
    weight = np.minimum(np.sqrt(between) / scale, max_weight)
    if not weight.any():
        raise ValueError("labels: no dimension separates the identities")
    return FeatureStats(mean=mean, scale=scale, weight=weight)


class HandcraftedFeatures:
    """The seed-B feature extractor (see module docstring). Implements :class:`FeatureExtractor`."""

    dim = RAW_DIM

    def __init__(self, stats: FeatureStats | None = None, crop_px: int = 32, warmup: int = 200) -> None:
        if crop_px < 16:
            raise ValueError(f"crop_px must be at least 16, got {crop_px}")
        if warmup < 2:
            raise ValueError(f"warmup must be at least 2, got {warmup}")
        self.crop_px = crop_px
        self.warmup = warmup
        self.stats_ = stats
        self._sum = np.zeros(RAW_DIM)
        self._sumsq = np.zeros(RAW_DIM)
        self._count = 0

    def __call__(self, image: np.ndarray, xywh: np.ndarray) -> np.ndarray:
        """``(n, RAW_DIM)`` standardised, block-weighted, L2-normalised features of the boxes."""
        return self.normalise(self.raw(image, xywh))

    def raw(self, image: np.ndarray, xywh: np.ndarray) -> np.ndarray:
        """``(n, RAW_DIM)`` raw features of boxes ``xywh (n, 4)`` in ``image (h, w, 3)`` BGR uint8."""
        return raw_features(crop_boxes(image, xywh, self.crop_px))

    def normalise(self, raw: np.ndarray) -> np.ndarray:
        """Standardise (fitted or running statistics), weight blocks, L2-normalise rows."""
        raw = np.asarray(raw, dtype=float)
        if raw.ndim != 2 or raw.shape[1] != RAW_DIM:
            raise ValueError(f"raw: expected shape (n, {RAW_DIM}), got {raw.shape}")
        if self.stats_ is None:
            self._observe(raw)
            mean = self._sum / max(self._count, 1)
            var = self._sumsq / max(self._count, 1) - mean**2
            scale = np.sqrt(np.maximum(var, 1e-6)) if self._count >= 2 else np.ones(RAW_DIM)
        else:
            mean, scale = self.stats_.mean, self.stats_.scale
        weight = _block_weights() if self.stats_ is None or self.stats_.weight is None else self.stats_.weight
        z = (raw - mean) / scale * weight
        norm = np.linalg.norm(z, axis=1, keepdims=True)
        return z / np.maximum(norm, 1e-12)

    def _observe(self, raw: np.ndarray) -> None:
        take = raw[: max(self.warmup - self._count, 0)]
        if len(take):
            self._sum += take.sum(axis=0)
            self._sumsq += (take**2).sum(axis=0)
            self._count += len(take)
            if self._count >= self.warmup:
                mean = self._sum / self._count
                std = np.sqrt(np.maximum(self._sumsq / self._count - mean**2, 1e-6))
                self.stats_ = FeatureStats(mean=mean, scale=std)


def crop_boxes(image: np.ndarray, xywh: np.ndarray, size: int | tuple[int, int]) -> np.ndarray:
    """``(n, size, size, 3)`` uint8 crops (``size`` may be ``(width, height)``) of boxes ``xywh (n, 4)`` (px), clipped
    to the image; a box wholly outside gives a black crop."""
    with needs("cv2"):
        import cv2

    img = np.asarray(image)
    if img.ndim != 3 or img.shape[2] != 3 or img.dtype != np.uint8:
        raise ValueError(f"image: expected (h, w, 3) uint8, got {img.shape} {img.dtype}")
    boxes = np.asarray(xywh, dtype=float).reshape(-1, 4)
    h, w = img.shape[:2]
    x0 = np.clip(np.floor(boxes[:, 0]), 0, w).astype(int)
    y0 = np.clip(np.floor(boxes[:, 1]), 0, h).astype(int)
    x1 = np.clip(np.ceil(boxes[:, 0] + boxes[:, 2]), 0, w).astype(int)
    y1 = np.clip(np.ceil(boxes[:, 1] + boxes[:, 3]), 0, h).astype(int)
    cw, ch = (size, size) if isinstance(size, int) else (int(size[0]), int(size[1]))
    out = np.zeros((len(boxes), ch, cw, 3), dtype=np.uint8)
    for i in range(len(boxes)):
        if x1[i] > x0[i] and y1[i] > y0[i]:
            out[i] = cv2.resize(img[y0[i] : y1[i], x0[i] : x1[i]], (cw, ch), interpolation=cv2.INTER_AREA)
    return out


def raw_features(crops: np.ndarray) -> np.ndarray:
    """``(n, RAW_DIM)`` raw features of square BGR uint8 crops ``(n, s, s, 3)``."""
    with needs("cv2"):
        import cv2

    crops = np.asarray(crops)
    if crops.ndim != 4 or crops.shape[1] != crops.shape[2] or crops.shape[3] != 3:
        raise ValueError(f"crops: expected (n, s, s, 3), got {crops.shape}")
    n, s = crops.shape[0], crops.shape[1]
    if n == 0:
        return np.zeros((0, RAW_DIM))
    flat = (crops.reshape(n * s, s, 3).astype(np.float32)) / 255.0
    lab = cv2.cvtColor(flat, cv2.COLOR_BGR2LAB).reshape(n, s, s, 3).astype(float)
    mask = _foreground(lab)
    weight = mask.astype(float)
    empty = weight.sum(axis=(1, 2)) < 4
    weight[empty] = 1.0  # no foreground found: describe the whole crop
    grey = lab[..., 0] / np.maximum(lab[..., 0].mean(axis=(1, 2), keepdims=True), 1.0)
    contour, hull = _shape_stats(mask, s)
    return np.hstack(
        [_colour(lab, weight), _frequency(grey), np.hstack([_edges(grey), contour]), hull, _hu(weight)]
    )


def _foreground(lab: np.ndarray) -> np.ndarray:
    """``(n, s, s)`` bool: pixels that differ from the crop border's median colour."""
    border = np.concatenate(
        [lab[:, :2].reshape(len(lab), -1, 3), lab[:, -2:].reshape(len(lab), -1, 3),
         lab[:, :, :2].reshape(len(lab), -1, 3), lab[:, :, -2:].reshape(len(lab), -1, 3)],
        axis=1,
    )
    background = np.median(border, axis=1)  # (n, 3)
    diff = np.linalg.norm(lab - background[:, None, None, :], axis=-1)
    flat = diff.reshape(len(lab), -1)
    k95 = int(0.95 * (flat.shape[1] - 1))
    thresh = np.maximum(0.5 * np.partition(flat, k95, axis=1)[:, k95], 4.0)
    return diff > thresh[:, None, None]


def _weighted_hist(values: np.ndarray, weight: np.ndarray, edges: np.ndarray) -> np.ndarray:
    """Per-row normalised histograms ``(n, len(edges)-1)`` of ``values (n, p)`` with ``weight (n, p)``."""
    k = len(edges) - 1
    bins = np.clip(np.searchsorted(edges, values, side="right") - 1, 0, k - 1)
    out = _row_bincount(bins, weight, k)
    return out / np.maximum(out.sum(axis=1, keepdims=True), 1e-12)


def _row_bincount(bins: np.ndarray, weight: np.ndarray, k: int) -> np.ndarray:
    """``(n, k)`` weighted counts of integer ``bins (n, p)`` in ``[0, k)``, one histogram per row."""
    n = len(bins)
    offset = (np.arange(n) * k)[:, None]
    return np.bincount((bins + offset).ravel(), weights=weight.ravel(), minlength=n * k).reshape(n, k)


def _colour(lab: np.ndarray, weight: np.ndarray) -> np.ndarray:
    n = len(lab)
    w = weight.reshape(n, -1)
    total = w.sum(axis=1, keepdims=True)
    chans = lab.reshape(n, -1, 3)
    mean = np.einsum("np,npc->nc", w, chans) / total
    var = np.einsum("np,npc->nc", w, (chans - mean[:, None, :]) ** 2) / total
    std = np.sqrt(var)
    rel_l = std[:, 0] / np.maximum(mean[:, 0], 1.0)
    a_edges = np.array([-128.0, -12.0, 0.0, 12.0, 128.0])
    ab_bin = (np.clip(np.searchsorted(a_edges, chans[..., 1], side="right") - 1, 0, 3) * 4
              + np.clip(np.searchsorted(a_edges, chans[..., 2], side="right") - 1, 0, 3))
    ab_hist = _row_bincount(ab_bin, w, 16) / total
    l_rel = chans[..., 0] / np.maximum(mean[:, :1], 1.0)
    l_hist = _weighted_hist(l_rel, w, np.array([0.0, 0.6, 0.9, 1.1, 1.5, np.inf]))[:, [0, 1, 3, 4]]
    return np.hstack([mean[:, 1:], std[:, 1:], rel_l[:, None], ab_hist, l_hist])


def _frequency(grey: np.ndarray, bands: int = 6) -> np.ndarray:
    n, s, _ = grey.shape
    spec = np.abs(np.fft.rfft2(grey - grey.mean(axis=(1, 2), keepdims=True)))  # (n, s, s//2+1)
    fy = np.fft.fftfreq(s)[:, None]
    fx = np.fft.rfftfreq(s)[None, :]
    radius = np.sqrt(fx**2 + fy**2) / 0.5  # 0 .. ~1.41, 1 at Nyquist
    band = np.minimum((radius * bands).astype(int), bands - 1).ravel()
    keep = radius.ravel() > 0
    sums = spec.reshape(n, -1)[:, keep] @ np.eye(bands)[band[keep]]
    counts = np.bincount(band[keep], minlength=bands)
    return np.log1p(sums / np.maximum(counts, 1) / s)


def _edges(grey: np.ndarray) -> np.ndarray:
    gx = np.zeros_like(grey)
    gy = np.zeros_like(grey)
    gx[:, :, 1:-1] = grey[:, :, 2:] - grey[:, :, :-2]
    gy[:, 1:-1, :] = grey[:, 2:, :] - grey[:, :-2, :]
    mag = np.hypot(gx, gy).reshape(len(grey), -1)
    density = (mag > 2.0 * mag.mean(axis=1, keepdims=True)).mean(axis=1)
    angle = np.mod(np.arctan2(gy, gx), np.pi).reshape(len(grey), -1)  # orientation, sign-free
    hist = _weighted_hist(angle, mag, np.linspace(0.0, np.pi, 9))
    return np.hstack([density[:, None], hist])


def _shape_stats(mask: np.ndarray, s: int) -> tuple[np.ndarray, np.ndarray]:
    """Contour statistics ``(n, 3)`` and convex-hull statistics ``(n, 5)`` of each foreground mask."""
    with needs("cv2"):
        import cv2

    n = len(mask)
    contour = np.zeros((n, 3))
    hull_stats = np.zeros((n, 5))
    m8 = mask.astype(np.uint8)
    for i in range(n):
        found, _ = cv2.findContours(m8[i], cv2.RETR_EXTERNAL, cv2.CHAIN_APPROX_SIMPLE)
        if not found:
            continue
        areas = np.array([cv2.contourArea(c) for c in found])
        big = found[int(areas.argmax())]
        area = max(float(areas.max()), 1.0)
        perimeter = cv2.arcLength(big, True)
        (_, _), (rw, rh), _ = cv2.minAreaRect(big)
        elong = min(rw, rh) / max(rw, rh, 1.0)
        contour[i] = [np.log1p(len(found)), 4 * np.pi * area / max(perimeter**2, 1.0), elong]
        hull_idx = cv2.convexHull(big, returnPoints=False)
        hull_area = max(cv2.contourArea(big[hull_idx.ravel()]), 1.0)
        size = np.sqrt(hull_area)
        depths: np.ndarray = np.zeros(0)
        if len(hull_idx) > 3 and len(big) > 3:
            try:
                defects = cv2.convexityDefects(big, np.sort(hull_idx, axis=0))
            except cv2.error:
                defects = None
            if defects is not None:
                depths = defects.reshape(-1, 4)[:, 3] / 256.0
                depths = depths[depths > 1.0]
        hull_stats[i] = [
            area / hull_area,
            hull_area / (s * s),
            np.log1p(len(depths)),
            depths.mean() / size if len(depths) else 0.0,
            depths.max() / size if len(depths) else 0.0,
        ]
    return contour, hull_stats


def _hu(weight: np.ndarray) -> np.ndarray:
    """Log-scaled Hu moment invariants ``(n, 7)`` of the masks ``weight (n, s, s)``, vectorised."""
    s = weight.shape[1]
    coord = np.arange(s, dtype=float)
    m00 = weight.sum(axis=(1, 2))
    col_sum = weight.sum(axis=1)  # (n, s) over rows, indexed by x
    row_sum = weight.sum(axis=2)  # (n, s) indexed by y
    dx = coord[None] - ((col_sum @ coord) / m00)[:, None]  # (n, s)
    dy = coord[None] - ((row_sum @ coord) / m00)[:, None]
    # Central moments as separable sums: mu_pq = sum_y dy^q sum_x w dx^p.
    wx = [np.einsum("nyx,nx->ny", weight, dx**p) for p in range(4)]

    def eta(p: int, q: int) -> np.ndarray:
        mu = np.einsum("ny,ny->n", wx[p], dy**q)
        return mu / m00 ** (1 + (p + q) / 2)

    n20, n02, n11 = eta(2, 0), eta(0, 2), eta(1, 1)
    n30, n03, n21, n12 = eta(3, 0), eta(0, 3), eta(2, 1), eta(1, 2)
    a, b = n30 + n12, n21 + n03
    h = np.stack(
        [
            n20 + n02,
            (n20 - n02) ** 2 + 4 * n11**2,
            (n30 - 3 * n12) ** 2 + (3 * n21 - n03) ** 2,
            a**2 + b**2,
            (n30 - 3 * n12) * a * (a**2 - 3 * b**2) + (3 * n21 - n03) * b * (3 * a**2 - b**2),
            (n20 - n02) * (a**2 - b**2) + 4 * n11 * a * b,
            (3 * n21 - n03) * a * (a**2 - 3 * b**2) - (n30 - 3 * n12) * b * (3 * a**2 - b**2),
        ],
        axis=1,
    )
    # Signed log scale, continuous through zero (the textbook -sign·log10|h| jumps there).
    return np.sign(h) * np.log10(1.0 + np.abs(h) / _HU_FLOOR)
