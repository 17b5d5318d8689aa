"""Blob detector settings estimated from ``sample`` frames of the video itself: stabilisation, polarity, noise σ, the
threshold (4-20 σ: counting N blobs most often, else the plateau of the count), area bounds ``A/5`` to ``6·A`` around
the typical target area and morphology from the targets' thickness. The rules: docs/blobs.md."""

from __future__ import annotations

import hashlib
import math
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

from lookalike._optional import needs
from lookalike.vision.blob import BlobConfig, median_frame, spread
from lookalike.vision.hog_features import as_bgr_image

__all__ = ["BOX_TRACKER_PARAMS", "BlobEstimate", "TargetCount", "estimate_blob_config", "frame_counts",
           "infer_target_count", "sample_frames"]

SOURCE_HASH = hashlib.sha256(Path(__file__).read_bytes()).hexdigest()
"""SHA-256 of this module's source as imported (cache keys name the code that runs, not the file on disk)."""

_FACTORS = (4.0, 6.0, 8.0, 10.0, 14.0, 20.0)  # candidate thresholds in noise σ
_THRESHOLD_RANGE = (8.0, 100.0)  # grey levels
_MIN_AREA_FRACTION = 1 / 5
_MAX_AREA_FACTOR = 6.0
_ALIGN_GAIN = 0.8  # stabilise when alignment cuts the spread of differences from the median by 20%+
_WORK_SIDE_PX = 640
_MIN_HIT_SHARE = 0.2  # a threshold must count exactly N blobs in this share of the samples to be chosen by N
_PERSISTENT_SHARE = 0.3  # pixels in the foreground of more sampled frames than this are not targets


@dataclass(frozen=True)
class BlobEstimate:
    """An estimated :class:`BlobConfig` and its statistics: background ``noise`` σ (grey levels), typical
    ``target_area_px`` (px²), median inscribed radius ``half_thickness_px`` and camera ``shake_px`` (px), the
    foreground's ``dark_share``, the median blobs per frame of each candidate threshold, and ``n_targets`` given."""

    config: BlobConfig
    noise: float
    target_area_px: float
    half_thickness_px: float
    shake_px: float
    dark_share: float
    counts: dict[float, float] = field(default_factory=dict)  # threshold -> median blobs per frame
    n_targets: int | None = None

    @property
    def typical_count(self) -> int:
        """Median blobs per sampled frame at the chosen threshold (the number of targets, when all are in view)."""
        return int(round(self.counts.get(self.config.threshold, 0.0)))

    @property
    def summary(self) -> str:
        """One line per decision, with the ``--blob KEY=VALUE`` that overrides it."""
        c = self.config
        polarity = {"dark": "darker than the background", "bright": "brighter than the background",
                    "any": "darker and brighter than the background"}[c.polarity]
        lines = [
            f"polarity={c.polarity}: targets {polarity} ({100 * self.dark_share:.0f}% of the foreground is darker)",
            f"threshold={c.threshold:g}: grey levels from the background (noise σ {self.noise:.1f})",
            f"min_area_px={c.min_area_px:g} max_area_px={c.max_area_px:g}: typical target "
            f"{self.target_area_px:.0f} px²",
            f"open_px={c.open_px} close_px={c.close_px}: targets about {2 * self.half_thickness_px:.0f} px thick",
            f"stabilise={'true' if c.stabilise else 'false'}: camera moves {self.shake_px:.1f} px (median)",
            f"about {self.typical_count} blobs per frame" + (f" ({self.n_targets} targets given)"
                                                            if self.n_targets else ""),
        ]
        return "\n".join(lines)


MIN_SIDE_PX = 16  # frames narrower or lower than this cannot hold a blob against a background (pixels)
_IMAGE_SUFFIXES = (".jpg", ".jpeg", ".png", ".bmp")  # a folder given as the video: its images (as io.video_frames)


def _odd(value: float, lo: int, hi: int) -> int:
    v = int(min(max(round(value), lo), hi))
    return v if v % 2 else v + 1 if v + 1 <= hi else v - 1


def sample_frames(video: str | Path, count: int) -> list[np.ndarray]:
    """Up to ``count`` BGR uint8 frames spread evenly over a video file or an image folder (by name), in one pass that
    converts only the frames kept."""
    with needs("cv2"):
        import cv2

    folder = Path(video)
    if folder.is_dir():
        paths = sorted(q for q in folder.iterdir() if q.suffix.lower() in _IMAGE_SUFFIXES)
        images: list[np.ndarray] = []
        for i in spread(len(paths), count):
            image = cv2.imread(str(paths[i]), cv2.IMREAD_COLOR)
            if image is None:
                raise ValueError(f"video: {paths[i]} is not a readable image")
            if images and image.shape != images[0].shape:
                raise ValueError(f"video: {paths[i]} is {image.shape[1]}x{image.shape[0]} px, the folder's first "
                                 f"image {images[0].shape[1]}x{images[0].shape[0]}; every frame needs one size")
            images.append(image)
        if not images:
            raise ValueError(f"video: folder {folder} holds no readable images ({', '.join(_IMAGE_SUFFIXES)})")
        return images
    cap = cv2.VideoCapture(str(video))
    if not cap.isOpened():
        raise ValueError(f"video: cannot open {video}")
    try:
        total = int(cap.get(cv2.CAP_PROP_FRAME_COUNT))
        wanted = set(spread(total, count).tolist()) if total > 0 else None  # None: keep all, pick after
        frames: list[np.ndarray] = []
        k = 0
        while cap.grab():  # (a frame not kept is decoded but never converted to BGR)
            if wanted is None or k in wanted:
                ok, frame = cap.retrieve()
                if not ok:
                    break
                frames.append(frame)
            k += 1
        if wanted is None:
            frames = [frames[i] for i in spread(len(frames), count)]
        elif k < total - max(2, total // 20):  # (as io.video_frames.source_frames says it)
            raise ValueError(f"video: {video} declares {total} frames but only {k} could be read "
                             "(truncated or damaged?)")
    finally:
        cap.release()
    if not frames:
        raise ValueError(f"video: {video} has no readable frames")
    return frames


def _spread(stack: np.ndarray, median: np.ndarray) -> float:
    """90th percentile of the absolute differences of ``stack`` from its per-pixel ``median`` (grey levels)."""
    diff = stack - median
    return float(np.percentile(np.abs(diff, out=diff), 90, overwrite_input=True))


def _dark_bright(stack: np.ndarray, background: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(n, h, w)`` float32 darkening and brightening (>= 0, the most changed channel) of a ``(n, h, w, 3)`` uint8 or
    float32 ``stack`` against its ``(h, w, 3)`` float32 ``background``: ``max(-min_c(stack - background), 0)`` and
    ``max(max_c(stack - background), 0)`` in float32, a frame at a time into one buffer."""
    with needs("cv2"):
        import cv2

    dark = np.empty(stack.shape[:3], np.float32)
    bright = np.empty_like(dark)
    d = np.empty_like(background)
    for im, lo, hi in zip(stack, dark, bright):
        cv2.subtract(im, background, dst=d, dtype=cv2.CV_32F)
        np.minimum(d[..., 0], d[..., 1], out=lo)
        np.minimum(lo, d[..., 2], out=lo)
        np.negative(lo, out=lo)
        np.maximum(lo, 0, out=lo)
        np.maximum(d[..., 0], d[..., 1], out=hi)
        np.maximum(hi, d[..., 2], out=hi)
        np.maximum(hi, 0, out=hi)
    return dark, bright


def _shifts(grey: list[np.ndarray]) -> np.ndarray:
    """``(n, 2)`` translation (px) of each frame against the median of all (phase correlation)."""
    with needs("cv2"):
        import cv2

    reference = median_frame(np.stack(grey))
    window = cv2.createHanningWindow(reference.shape[::-1], cv2.CV_32F)
    moves = np.array([cv2.phaseCorrelate(reference, g, window)[0] for g in grey])
    return moves - moves[0]


def _components(mask: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Areas (px²) and labels of the 8-connected components of a uint8 mask."""
    with needs("cv2"):
        import cv2

    _, labels, stats, _ = cv2.connectedComponentsWithStatsWithAlgorithm(mask, 8, cv2.CV_32S, cv2.CCL_BBDT)
    return stats[1:, cv2.CC_STAT_AREA].astype(float), labels


def _target_area(areas: list[np.ndarray]) -> float:
    """Area-weighted median of the components' areas (px²), blind to small noise specks."""
    pooled = np.concatenate(areas) if areas else np.zeros(0)
    if not len(pooled):
        return 0.0
    order = np.sort(pooled)
    cum = np.cumsum(order)
    return float(order[np.searchsorted(cum, cum[-1] / 2)])


def _radii(masks: list[np.ndarray], area: float) -> list[float]:
    """Largest inscribed radius (px) of every component of ``masks`` with a target's area."""
    with needs("cv2"):
        import cv2

    radii: list[float] = []
    for mask in masks:
        _, labels = _components(mask)
        dist = cv2.distanceTransform(mask, cv2.DIST_L2, 3)
        count = int(labels.max())
        if count:
            peak = np.zeros(count + 1)
            inside = np.flatnonzero(labels)  # (the background, label 0, is never kept)
            np.maximum.at(peak, labels.ravel()[inside], dist.ravel()[inside])
            sizes = np.bincount(labels.ravel(), minlength=count + 1)
            ok = (sizes >= area * _MIN_AREA_FRACTION) & (sizes <= area * _MAX_AREA_FACTOR)
            ok[0] = False
            radii.extend(peak[ok].tolist())
    return radii


def _pick_frames(frames: str | Path | Iterable[np.ndarray], sample: int) -> list[np.ndarray]:
    """Up to ``sample`` frames spread over ``frames`` (a video path or frames); ``ValueError`` for none or tiny ones."""
    if isinstance(frames, (str, Path)):
        picked = sample_frames(frames, sample)
    else:
        every = list(frames)
        if not every:
            raise ValueError("frames: no frames to estimate blob settings on")
        picked = [every[i] for i in spread(len(every), sample)]
    height, width = as_bgr_image(picked[0], "frames[0]").shape[:2]
    if min(height, width) < MIN_SIDE_PX:
        what = f"video: {frames}" if isinstance(frames, (str, Path)) else "frames"
        raise ValueError(f"{what}: {width}x{height} px; the blob detector needs frames of at least {MIN_SIDE_PX} px "
                         "a side")
    return picked


def estimate_blob_config(frames: str | Path | Iterable[np.ndarray], n_targets: int | None = None, *,
                         sample: int = 25, shake_px: float = 0.5, polarity_ratio: float = 0.1,
                         base: BlobConfig | None = None,
                         progress: Callable[[str, int], Callable[[], None]] | None = None) -> BlobEstimate:
    """Blob detector settings estimated from a video (a path, or its ``(h, w, 3)`` BGR frames), knowing
    ``n_targets`` or not; ``base`` gives the settings not estimated. ``progress(description, total)`` gives a
    function called after each of ``total`` steps."""
    with needs("cv2"):
        import cv2

    if n_targets is not None and int(n_targets) < 1:
        raise ValueError(f"n_targets must be >= 1, got {n_targets}")
    base = base or BlobConfig()
    total = 2 + len(_FACTORS)
    step = progress("estimating blob settings", total) if progress is not None else (lambda: None)
    picked = _pick_frames(frames, sample)
    step()
    blur = base.blur_px
    height, width = as_bgr_image(picked[0], "frames[0]").shape[:2]
    scale = min(1.0, _WORK_SIDE_PX / max(height, width))  # statistics on a reduced copy, for speed
    small = []
    for i, frame in enumerate(picked):
        img = as_bgr_image(frame, f"frames[{i}]")
        img = cv2.GaussianBlur(img, (blur, blur), 0) if blur > 1 else img
        small.append(cv2.resize(img, None, fx=scale, fy=scale, interpolation=cv2.INTER_AREA) if scale < 1 else img)
    stack: np.ndarray = np.stack(small)  # uint8; float32 once aligned
    del small
    grey = [im.astype(np.float32).mean(axis=2) for im in stack]
    moves = _shifts(grey) if len(grey) > 1 else np.zeros((1, 2))
    shake = float(np.median(np.hypot(moves[:, 0], moves[:, 1]))) / scale
    background = median_frame(stack)
    stabilise = False
    if shake > shake_px:  # keep the alignment only if it makes the frames agree better with their median
        h, w = grey[0].shape
        stack = stack.astype(np.float32)
        aligned = np.empty_like(stack)
        for im, (dx, dy), out in zip(stack, moves, aligned):
            cv2.warpAffine(im, np.array([[1, 0, -dx], [0, 1, -dy]], dtype=np.float32), (w, h), dst=out,
                           borderMode=cv2.BORDER_REPLICATE)
        aligned_background = median_frame(aligned)
        if _spread(aligned, aligned_background) < _ALIGN_GAIN * _spread(stack, background):
            stack, background, stabilise = aligned, aligned_background, True
    dark, bright = _dark_bright(stack, background)
    del stack
    noise = max(1.4826 * float(np.median(np.maximum(dark, bright), overwrite_input=True)), 0.5)
    cut = min(max(6 * noise, _THRESHOLD_RANGE[0]), _THRESHOLD_RANGE[1])
    dark_mass, bright_mass = float((dark > cut).sum()), float((bright > cut).sum())
    dark_share = dark_mass / max(dark_mass + bright_mass, 1.0)
    if bright_mass < polarity_ratio * dark_mass:
        polarity, signal = "dark", dark
    elif dark_mass < polarity_ratio * bright_mass:
        polarity, signal = "bright", bright
    else:
        polarity, signal = "any", np.maximum(dark, bright)
    kernel = cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (3, 3)) if scale > 0.67 else None
    lo, hi = _THRESHOLD_RANGE
    candidates = sorted({float(round(min(max(f * noise, lo), hi))) for f in _FACTORS})
    for _ in range(1 + len(_FACTORS) - len(candidates)):  # the background; thresholds that coincide
        step()
    results = {}
    for thr in candidates:
        per_frame, masks = [], []
        raw: list[np.ndarray] = [cv2.compare(sig, np.array([thr]), cv2.CMP_GT) for sig in signal]  # 255: sig > thr
        if kernel is not None:
            raw = [cv2.morphologyEx(m, cv2.MORPH_OPEN, kernel) for m in raw]
        persistent = np.count_nonzero(np.stack(raw), axis=0) / len(raw) > _PERSISTENT_SHARE
        for mask in raw:
            areas, labels = _components(mask)
            moving = np.bincount(labels.ravel(), weights=~persistent.ravel(), minlength=len(areas) + 1)[1:]
            per_frame.append(areas[moving >= areas / 2])  # mostly where foreground is rare: a moving target
            masks.append(mask)
        area = _target_area(per_frame)
        lo_a, hi_a = area * _MIN_AREA_FRACTION, area * _MAX_AREA_FACTOR
        counts = np.array([int(((a >= lo_a) & (a <= hi_a)).sum()) for a in per_frame])
        results[thr] = (area, counts, masks)
        step()
    medians = {thr: float(np.median(r[1])) for thr, r in results.items()}
    hit = {thr: float(np.mean(r[1] == n_targets)) for thr, r in results.items()} if n_targets else {}
    if hit and max(hit.values()) >= _MIN_HIT_SHARE:
        chosen = [thr for thr in candidates if hit[thr] == max(hit.values())]
    else:  # no N, or no threshold counts N blobs often (targets out of view, partly annotated clips)
        values, freq = np.unique([medians[t] for t in candidates if medians[t] > 0] or [0.0], return_counts=True)
        plateau = values[freq == freq.max()].max()
        chosen = [thr for thr in candidates if medians[thr] == plateau]
    threshold = chosen[len(chosen) // 2]
    area, _, masks = results[threshold]
    if area <= 0:
        raise ValueError("frames: no foreground differs from the background; is the camera static and "
                         "do the targets move?")
    radii = _radii(masks, area)
    r = (float(np.median(radii)) if radii else 1.0) / scale
    area /= scale**2
    config = replace(base, threshold=float(threshold), polarity=polarity,
                     min_area_px=float(round(area * _MIN_AREA_FRACTION)),
                     max_area_px=float(round(area * _MAX_AREA_FACTOR)) if math.isfinite(area) else math.inf,
                     open_px=_odd(r, 3, 15), close_px=_odd(2 * r, 3, 15), stabilise=stabilise)
    return BlobEstimate(config=config, noise=noise, target_area_px=area, half_thickness_px=r, shake_px=shake,
                        dark_share=dark_share, counts=medians, n_targets=int(n_targets) if n_targets else None)


BOX_TRACKER_PARAMS: dict[str, float] = {"match_iou": 0.01}
"""``boxtrack`` parameters for blob detections: a track takes any blob its predicted box overlaps (docs/blobs.md)."""

_MAJORITY = 0.5  # a count holding in more than this share of the frames is an arena's number of targets


@dataclass(frozen=True)
class TargetCount:
    """The number of targets read off a video's blob counts: the most common count ``n`` (0 without blobs), the
    ``share`` of the ``frames`` counted showing it."""

    n: int
    share: float
    frames: int

    @property
    def closed(self) -> bool:
        """Whether ``n`` makes a closed set: the same count in a strict majority of the frames."""
        return self.n >= 1 and self.share > _MAJORITY

    @property
    def summary(self) -> str:
        """One line saying what was inferred and how to override it."""
        seen = f"{self.n} blobs in {100 * self.share:.0f}% of the {self.frames} frames"
        if self.closed:
            return (f"inferred {self.n} targets from the video: {seen}; a closed set of {self.n} "
                    f"(pass --targets N to override, --targets 0 for an open set)")
        return (f"no number of targets inferred from the video: at most {seen} (a closed set needs a "
                f"majority); tracking an open set (pass --targets N for a closed set)")


def infer_target_count(counts: np.ndarray) -> TargetCount:
    """The most common of ``counts``, blobs per frame (the larger on a tie), with the share of frames showing it."""
    counts = np.asarray(counts, dtype=int).ravel()
    if not len(counts) or counts.max(initial=0) <= 0:
        return TargetCount(0, 0.0, len(counts))
    freq = np.bincount(np.maximum(counts, 0))
    n = int(np.flatnonzero(freq == freq.max()).max())
    return TargetCount(n, float(freq[n]) / len(counts), len(counts))


def frame_counts(det_rows: np.ndarray, n_frames: int) -> np.ndarray:
    """Detections per frame ``(n_frames,)`` from MOTChallenge rows ``(k, >=1)`` (1-based frames)."""
    rows = np.asarray(det_rows, dtype=float)
    frames = rows[:, 0].astype(int) if rows.ndim == 2 and len(rows) else np.zeros(0, dtype=int)
    length = max(int(n_frames), int(frames.max(initial=0)))
    return np.bincount(frames, minlength=length + 1)[1 : length + 1]
