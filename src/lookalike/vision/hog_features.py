"""Image checks and HOG building blocks: soft-assigned orientation maps, their integral images (any rectangle in four
look-ups per bin), cell histograms and block descriptors. OpenCV is imported lazily."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from lookalike._optional import needs
from lookalike.vision.hog_kernels import compiled

BINS = 9  # unsigned orientation bins over [0, π)


def as_bgr_image(image: np.ndarray, name: str = "image") -> np.ndarray:
    """``image`` as ``(h, w, 3)`` uint8 BGR: grey replicated, alpha dropped, floats in [0, 1] scaled to 0..255, other
    integers clipped. Empty images, other shapes and non-finite values raise ``ValueError`` naming ``name``."""
    arr = np.asarray(image)
    if arr.size == 0:
        raise ValueError(f"{name}: empty image (shape {arr.shape})")
    if arr.ndim == 3 and arr.shape[2] == 1:
        arr = arr[:, :, 0]
    if arr.ndim == 2:
        arr = np.repeat(arr[:, :, None], 3, axis=2)
    elif arr.ndim == 3 and arr.shape[2] == 4:
        arr = arr[:, :, :3]
    if arr.ndim != 3 or arr.shape[2] != 3:
        raise ValueError(f"{name}: expected (h, w), (h, w, 1), (h, w, 3) or (h, w, 4), got shape {arr.shape}")
    if arr.dtype == np.uint8:
        return np.ascontiguousarray(arr)
    if arr.dtype == bool or not np.issubdtype(arr.dtype, np.number):
        raise ValueError(f"{name}: unsupported dtype {arr.dtype}; use uint8, an integer type or float in [0, 1]")
    if np.issubdtype(arr.dtype, np.floating):
        if not np.isfinite(arr).all():
            raise ValueError(f"{name}: contains NaN or infinity")
        peak = float(arr.max())
        scale = 255.0 if peak <= 1.0 else 1.0
        return np.clip(np.rint(arr * scale), 0, 255).astype(np.uint8)
    return np.clip(arr, 0, 255).astype(np.uint8)


def to_grey(image_bgr: np.ndarray) -> np.ndarray:
    """``(h, w)`` float32 luminance ``0.114 B + 0.587 G + 0.299 R`` (0..255) of a ``(h, w, 3)`` uint8 BGR image."""
    with needs("cv2"):
        import cv2

    img = np.ascontiguousarray(image_bgr)
    h, w = img.shape[:2]
    out = np.empty((h, w), np.float32)
    kernels = compiled()
    if kernels is not None and img.dtype == np.uint8 and img.ndim == 3 and img.shape[2] == 3:
        kernels["grey"](img, out)
        return out
    rows = max(1, _BAND_PIXELS // max(1, w))
    for y0 in range(0, h, rows):
        b, g, r = (c.astype(np.float32) for c in cv2.split(img[y0 : y0 + rows]))
        b *= np.float32(0.114)
        g *= np.float32(0.587)
        r *= np.float32(0.299)
        b += g
        np.add(b, r, out=out[y0 : y0 + rows])
    return out


def hue_channel(image_bgr: np.ndarray) -> np.ndarray:
    """``(h, w)`` float32 hue of a BGR uint8 image, scaled to 0..255 (OpenCV's full-range HSV)."""
    with needs("cv2"):
        import cv2

    return cv2.cvtColor(image_bgr, cv2.COLOR_BGR2HSV_FULL)[..., 0].astype(np.float32)


def _polar_gradients(g: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Magnitude and angle in [0, 2π) (float32 ``(h, w)``) of the central-difference gradients of ``g``."""
    with needs("cv2"):
        import cv2

    gx = cv2.Sobel(g, cv2.CV_32F, 1, 0, ksize=1)  # kernel [-1, 0, 1]: the central difference
    gy = cv2.Sobel(g, cv2.CV_32F, 0, 1, ksize=1)
    gx[:, 0] = gx[:, -1] = 0.0
    gy[0, :] = gy[-1, :] = 0.0
    mag, ang = cv2.cartToPolar(gx, gy)
    return mag, ang


def _gradient_bins(grey: np.ndarray, bins: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Gradients of ``grey (h, w)`` as ``(lower bin int32, its weight, the next bin's weight)``, all ``(h, w)``."""
    g = np.asarray(grey, dtype=np.float32)
    if g.ndim != 2:
        raise ValueError(f"grey: expected shape (h, w), got {g.shape}")
    mag, ang = _polar_gradients(g)
    ang -= np.float32(np.pi) * (ang >= np.pi)  # unsigned orientation in [0, π]
    ang *= np.float32(bins / np.pi)
    ang -= np.float32(0.5)  # bin centres at integers: ang in [-0.5, bins - 0.5]
    lo = np.floor(ang)
    ang -= lo
    w_hi = np.multiply(mag, ang, out=ang)
    # floor(ang) is -1 .. bins - 1; as unsigned, -1 is the largest value, so the minimum wraps it to bins - 1.
    lo_i = np.minimum(lo.astype(np.int32).view(np.uint32), np.uint32(bins - 1)).view(np.int32)
    return lo_i, np.subtract(mag, w_hi, out=mag), w_hi


def orientation_maps(grey: np.ndarray, bins: int = BINS) -> np.ndarray:
    """``(bins, h, w)`` float32 central-difference gradient magnitude of ``grey (h, w)``, soft-assigned to bins."""
    lo, w_lo, w_hi = _gradient_bins(grey, bins)
    out = np.empty((bins,) + lo.shape, dtype=np.float32)
    for b in range(bins):
        out[b] = np.where(lo == b, w_lo, 0.0) + np.where(lo == (b - 1) % bins, w_hi, 0.0)
    return out


def cell_histograms(grey: np.ndarray, cell_px: int, bins: int = BINS) -> np.ndarray:
    """``(bins, h // cell_px, w // cell_px)`` float64 orientation histograms of square cells (:func:`orientation_maps`
    summed per cell), in bands of cell rows that stay in cache; bit for bit the whole image's sums."""
    g = np.asarray(grey, dtype=np.float32)
    if g.ndim != 2:
        raise ValueError(f"grey: expected shape (h, w), got {g.shape}")
    h, w = g.shape
    ny, nx = h // cell_px, w // cell_px
    hist = np.empty(ny * nx * bins)
    band = max(1, _BAND_PIXELS // max(1, w * cell_px))  # cell rows per band
    kernels = compiled()
    if kernels is not None:
        _compiled_cell_histograms(kernels["cell_hist"], g, cell_px, bins, band, hist.reshape(ny, nx, bins))
        return hist.reshape(ny, nx, bins).transpose(2, 0, 1)
    for r0 in range(0, ny, band):
        r1 = min(ny, r0 + band)
        y0, y1 = r0 * cell_px, r1 * cell_px
        top, bottom = max(0, y0 - 1), min(h, y1 + 1)
        lo, w_lo, w_hi = _gradient_bins(g[top:bottom], bins)  # rows top, bottom - 1 are context or the border
        crop = (slice(y0 - top, y1 - top), slice(0, nx * cell_px))
        lo = lo[crop]
        base = _cell_base(r1 - r0, nx, cell_px, bins)
        n = (r1 - r0) * nx * bins
        part = np.bincount((base + lo).ravel(), w_lo[crop].astype(np.float64).ravel(), n)
        lo += 1
        lo *= lo != bins  # the next bin, wrapping bins to 0
        lo += base
        part += np.bincount(lo.ravel(), w_hi[crop].astype(np.float64).ravel(), n)
        hist[r0 * nx * bins : r1 * nx * bins] = part
    return hist.reshape(ny, nx, bins).transpose(2, 0, 1)


def _compiled_cell_histograms(kernel: Callable[..., None], g: np.ndarray, cell_px: int, bins: int, band: int,
                              out: np.ndarray) -> None:
    """:func:`cell_histograms` into ``out (ny, nx, bins)`` with the compiled binning and sums."""
    h = g.shape[0]
    ny, nx = out.shape[:2]
    scale = np.float32(bins / np.pi)
    for r0 in range(0, ny, band):
        r1 = min(ny, r0 + band)
        y0, y1 = r0 * cell_px, r1 * cell_px
        top, bottom = max(0, y0 - 1), min(h, y1 + 1)
        mag, ang = _polar_gradients(g[top:bottom])
        kernel(mag, ang, y0 - top, cell_px, bins, scale, out[r0:r1])


_BAND_PIXELS = 1 << 15  # pixels per band of cell_histograms
_BASES: dict[tuple[int, int, int, int], np.ndarray] = {}


def _cell_base(ny: int, nx: int, cell_px: int, bins: int) -> np.ndarray:
    """``(ny * cell_px, nx * cell_px)`` int32: each pixel's cell index times ``bins`` (cached per shape)."""
    key = (ny, nx, cell_px, bins)
    base = _BASES.get(key)
    if base is None:
        rows = (np.arange(ny * cell_px, dtype=np.int32) // cell_px) * (nx * bins)
        cols = (np.arange(nx * cell_px, dtype=np.int32) // cell_px) * bins
        base = rows[:, None] + cols[None, :]
        base.flags.writeable = False
        if len(_BASES) > 64:
            _BASES.clear()
        _BASES[key] = base
    return base


def integral_maps(maps: np.ndarray) -> np.ndarray:
    """Summed-area tables ``(c, h+1, w+1)`` float64 of ``maps (c, h, w)``; entry ``[c, y, x]`` is the sum over
    rows ``< y`` and columns ``< x``."""
    m = np.asarray(maps, dtype=np.float64)
    out = np.zeros((m.shape[0], m.shape[1] + 1, m.shape[2] + 1))
    np.cumsum(np.cumsum(m, axis=1), axis=2, out=out[:, 1:, 1:])
    return out


def block_descriptor(cell_sums: np.ndarray, eps: float = 1e-3) -> np.ndarray:
    """L2-normalised block descriptors ``(4 * bins, ...)`` of 2×2 cell sums ``(4, bins, ...)``; ``eps`` keeps flat
    regions near zero."""
    flat = cell_sums.reshape((-1,) + cell_sums.shape[2:])
    norm = np.sqrt((flat * flat).sum(axis=0, keepdims=True)) + eps
    return flat / norm


def dense_hog(channel: np.ndarray, cell_px: int, bins: int = BINS) -> np.ndarray:
    """Dense HOG of a ``(h, w)`` channel: cells of ``cell_px`` pixels, overlapping 2×2-cell blocks,
    each L2-normalised; returns a flat float32 vector of ``(h//cell - 1) * (w//cell - 1) * 4 * bins``."""
    c = np.asarray(channel, dtype=np.float32)
    ny, nx = c.shape[0] // cell_px, c.shape[1] // cell_px
    if ny < 2 or nx < 2:
        raise ValueError(f"channel: {c.shape} is smaller than 2×2 cells of {cell_px} px")
    maps = orientation_maps(c[: ny * cell_px, : nx * cell_px], bins)
    cells = maps.reshape(bins, ny, cell_px, nx, cell_px).sum(axis=(2, 4))  # (bins, ny, nx)
    quads = np.stack([cells[:, :-1, :-1], cells[:, :-1, 1:], cells[:, 1:, :-1], cells[:, 1:, 1:]])
    area = float(cell_px * cell_px)
    return block_descriptor(quads, eps=area).astype(np.float32).ravel()


def crop_window(grey: np.ndarray, xywh: np.ndarray, window_px: tuple[int, int], pad: float = 0.1) -> np.ndarray:
    """A ``(h+2, w+2)`` float32 crop of ``grey (H, W)`` around box ``xywh`` (px) at the window's aspect, with ``pad``
    (of the box height) of context and a 1-px margin."""
    with needs("cv2"):
        import cv2

    w_px, h_px = window_px
    x, y, w, h = (float(v) for v in xywh)
    cx, cy = x + w / 2, y + h / 2
    hh = h * (1.0 + 2.0 * pad)
    ww = hh * w_px / h_px
    sx, sy = ww / w_px, hh / h_px
    # Affine map from the output (with margin) to the source image.
    m = np.array([[sx, 0, cx - ww / 2 - sx], [0, sy, cy - hh / 2 - sy]], dtype=np.float32)
    return cv2.warpAffine(np.asarray(grey, np.float32), m, (w_px + 2, h_px + 2),
                          flags=cv2.INTER_LINEAR | cv2.WARP_INVERSE_MAP, borderMode=cv2.BORDER_REPLICATE)


def augment_windows(windows: np.ndarray, copies: int, rng: np.random.Generator, max_rot_deg: float = 15.0,
                    scale_std: float = 0.06, cutout: float = 0.5) -> np.ndarray:
    """``copies`` random variants of each ``(h, w)`` window: rotation within ±``max_rot_deg``, scale jitter, flip,
    and with probability ``cutout`` a rectangle filled with the window's mean."""
    with needs("cv2"):
        import cv2

    out = []
    for win in np.asarray(windows, np.float32):
        h, w = win.shape
        for _ in range(copies):
            ang = float(np.clip(rng.normal(0, max_rot_deg / 2), -max_rot_deg, max_rot_deg))
            m = cv2.getRotationMatrix2D((w / 2, h / 2), ang, float(np.exp(rng.normal(0, scale_std))))
            v = cv2.warpAffine(win, m, (w, h), borderMode=cv2.BORDER_REPLICATE)
            if rng.random() < 0.5:
                v = v[:, ::-1]
            if rng.random() < cutout:
                ch, cw = int(rng.integers(h // 8, h // 2)), int(rng.integers(w // 4, w // 2 + 1))
                y0, x0 = int(rng.integers(0, h - ch)), int(rng.integers(0, w - cw))
                v = v.copy()
                v[y0 : y0 + ch, x0 : x0 + cw] = v.mean()
            out.append(np.ascontiguousarray(v))
    return np.array(out, dtype=np.float32).reshape(-1, *np.asarray(windows).shape[1:])
