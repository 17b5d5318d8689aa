"""Blob detections of a whole video as MOTChallenge rows (``lookalike track --video V --detector blob``), with the
estimated settings and the user's overrides, cached on disk keyed by the video's content, settings and code."""

from __future__ import annotations

import dataclasses
import hashlib
import io
import json
import math
import os
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from lookalike._optional import needs
from lookalike.io.outputs import write_atomic
from lookalike.io.video_frames import source_frames
from lookalike.trackers.offline.online_look import shapes_by_box
from lookalike.types import Detections
from lookalike.types.mot_table import detection_rows
from lookalike.vision import blob_shape
from lookalike.vision.blob import BlobConfig, BlobDetector
from lookalike.vision.blob_auto import BlobEstimate, estimate_blob_config, sample_frames
from lookalike.vision.blob_shape import PART_SIZE, SHAPE_SIZE

Progress = Callable[[str, int], Callable[[], None]]  # (description, total steps) -> called after each step

_BOOL_TRUE = ("1", "true", "yes", "on")
_BOOL_FALSE = ("0", "false", "no", "off")


CACHE_ENV = "LOOKALIKE_CACHE"
_SOURCE_HASH = hashlib.sha256(Path(__file__).read_bytes() + Path(blob_shape.__file__).read_bytes()).hexdigest()
# (this module and the blob descriptions' as imported)


def blob_config(settings: list[str]) -> BlobConfig:
    """A :class:`BlobConfig` from ``KEY=VALUE`` strings of its fields (``threshold=40``); ``ValueError`` naming a bad
    key or value."""
    return BlobConfig(**blob_settings(settings))


def blob_settings(settings: list[str]) -> dict[str, Any]:
    """The ``KEY=VALUE`` strings of :func:`blob_config` as typed values (only the keys given)."""
    kinds = {f.name: str(f.type) for f in dataclasses.fields(BlobConfig)}
    values: dict[str, Any] = {}
    for text in settings:
        key, sep, raw = text.partition("=")
        key, raw = key.strip(), raw.strip()
        if not sep or not key:
            raise ValueError(f"--blob {text!r}: expected KEY=VALUE")
        if key not in kinds:
            raise ValueError(f"--blob {key}: unknown setting; choose from {', '.join(kinds)}")
        kind = kinds[key]
        try:
            if kind == "bool":
                if raw.lower() not in _BOOL_TRUE + _BOOL_FALSE:
                    raise ValueError
                values[key] = raw.lower() in _BOOL_TRUE
            elif kind == "int":
                values[key] = int(raw)
            elif kind == "float":
                values[key] = float(raw)
                if math.isnan(values[key]):
                    raise ValueError
            else:
                values[key] = raw
        except ValueError:
            raise ValueError(f"--blob {key}: expected a {kind}, got {raw!r}") from None
    return values


def auto_blob_config(video: Path | str, settings: list[str], n_targets: int | None = None,
                     cache: Path | None | bool = True, progress: Progress | None = None,
                     ) -> tuple[BlobConfig, BlobEstimate | None]:
    """The blob settings for ``video``: estimated (cached; skipped when ``settings`` give threshold, polarity and both
    areas), then ``KEY=VALUE`` ``settings`` on top; and the estimate or None. ``progress``: as for
    :func:`~lookalike.vision.blob_auto.estimate_blob_config`."""
    given = blob_settings(settings)
    if {"threshold", "polarity", "min_area_px", "max_area_px"} <= set(given):
        return BlobConfig(**given), None
    base = BlobConfig(**{k: v for k, v in given.items() if k in ("method", "blur_px", "history", "sample_every")})
    estimate = _cached_estimate(video, n_targets, base, cache, progress)
    return dataclasses.replace(estimate.config, **given), estimate


def _cached_estimate(video: Path | str, n_targets: int | None, base: BlobConfig,
                     cache: Path | None | bool, progress: Progress | None = None) -> BlobEstimate:
    if cache is False or cache is None:
        return _estimate(video, n_targets, base, progress)
    from lookalike.vision import blob_auto

    path = (cache_dir() if cache is True else Path(cache)) / "blobs" / (
        detection_cache_key(video, base, extra={"n_targets": n_targets, "estimate": blob_auto.SOURCE_HASH})
        + ".estimate.json")
    if path.is_file():
        try:
            data = json.loads(path.read_text())
            data["config"] = BlobConfig(**data["config"])
            data["counts"] = {float(k): float(v) for k, v in data["counts"].items()}
            return BlobEstimate(**data)
        except (OSError, ValueError, TypeError, KeyError):
            pass
    estimate = _estimate(video, n_targets, base, progress)
    content = dataclasses.asdict(estimate)
    content["counts"] = {repr(k): v for k, v in estimate.counts.items()}
    _write_atomic(path, json.dumps(content, default=float).encode())
    return estimate


ESTIMATE_FRAMES = 25  # frames the settings are estimated on (estimate_blob_config's sample)
_SAMPLE: dict[tuple[Any, ...], list[np.ndarray]] = {}  # the last sample read, for the median background


def _sampled(video: Path | str, count: int) -> list[np.ndarray]:
    """:func:`~lookalike.vision.blob_auto.sample_frames`, the last sample kept so that one read serves the estimate
    and the median background."""
    stat = os.stat(video)
    key = (str(Path(video).resolve()), stat.st_mtime_ns, stat.st_size, count)
    if key not in _SAMPLE:
        _SAMPLE.clear()
        _SAMPLE[key] = sample_frames(video, count)
    return _SAMPLE[key]


def _detector(video: Path | str, config: BlobConfig, split: bool = True) -> BlobDetector:
    """A blob detector for ``video`` giving shape vectors (and parts, with ``split``), its median background fitted on
    the sampled frames (the sample then let go)."""
    detector = BlobDetector(config, describe=True, split=split)
    if config.method == "median":
        detector.fit(_sampled(video, config.history))
    _SAMPLE.clear()
    return detector


def _estimate(video: Path | str, n_targets: int | None, base: BlobConfig, progress: Progress | None) -> BlobEstimate:
    """:func:`~lookalike.vision.blob_auto.estimate_blob_config` on the sampled frames, errors naming the video."""
    try:
        return estimate_blob_config(_sampled(video, ESTIMATE_FRAMES), n_targets, base=base, progress=progress)
    except ValueError as exc:
        if str(exc).startswith("frames"):
            raise ValueError(f"video: {video}{str(exc).removeprefix('frames')}") from None
        raise


def _write_atomic(path: Path, data: bytes) -> None:
    try:
        write_atomic(path, data)  # (a unique temporary file, removed on any failure)
    except OSError:
        pass  # a read-only cache folder: no cache, same result


def cache_dir() -> Path:
    """Where cached detections live: ``$LOOKALIKE_CACHE`` or ``~/.cache/lookalike``."""
    root = os.environ.get(CACHE_ENV)
    return Path(root) if root else Path.home() / ".cache" / "lookalike"


def _file_hash(path: Path) -> str:
    digest = hashlib.sha256()
    files = sorted(q for q in path.iterdir() if q.is_file()) if path.is_dir() else [path]
    for q in files:
        digest.update(q.name.encode())
        with open(q, "rb") as fh:
            for chunk in iter(lambda: fh.read(1 << 20), b""):
                digest.update(chunk)
    return digest.hexdigest()


def detection_cache_key(video: Path | str, config: BlobConfig, extra: dict[str, Any] | None = None) -> str:
    """The cache key of ``video``'s blob detections: its content, ``config``, lookalike, detector code and OpenCV."""
    with needs("cv2"):
        import cv2

    from lookalike._version import __version__
    from lookalike.vision import blob

    code = blob.SOURCE_HASH + _SOURCE_HASH  # the code as imported: a long run never files old rows under new code
    payload = json.dumps({"video": _file_hash(Path(video)), "config": dataclasses.asdict(config),
                          "version": __version__, "code": code, "opencv": cv2.__version__, **(extra or {})},
                         sort_keys=True, default=str)
    return hashlib.sha256(payload.encode()).hexdigest()[:32]


@dataclass(frozen=True)
class BlobRows:
    """A video's blob detections: MOTChallenge ``rows`` ``(n, 10)``, the number of ``frames``, each row's
    :func:`~lookalike.vision.blob_shape.blob_shapes` vector ``shapes`` ``(n, SHAPE_SIZE)`` and its
    :func:`~lookalike.vision.blob_shape.blob_part_vectors` vector ``parts`` ``(n, PART_SIZE)`` (NaN: not split);
    ``split``: whether large blobs were split at all (False: every part NaN, detected where no parts are read)."""

    rows: np.ndarray
    frames: int
    shapes: np.ndarray
    parts: np.ndarray
    split: bool = True


def cached_blob_detections(video: Path | str, config: BlobConfig, advance: Callable[[], None] | None = None,
                           cache: Path | None | bool = True, split: bool = True) -> BlobRows:
    """:func:`blob_detections` through the cache (``cache``: a folder, ``True`` for :func:`cache_dir`, ``False`` or
    None for none; ``split``: as for :func:`load_blob_detections`)."""
    found = load_blob_detections(video, config, cache, split)
    if found is None:
        found = blob_detections(video, config, advance, split)
        store_blob_detections(video, config, found, cache)
    return found


def _cache_file(video: Path | str, config: BlobConfig, cache: Path | None | bool) -> Path | None:
    if cache is False or cache is None:
        return None
    return (cache_dir() if cache is True else Path(cache)) / "blobs" / f"{detection_cache_key(video, config)}.npz"


def load_blob_detections(video: Path | str, config: BlobConfig, cache: Path | None | bool = True,
                         split: bool = True) -> BlobRows | None:
    """``video``'s blob detections with ``config`` from the cache, or None when not there (with ``split``, also when
    they were stored without parts)."""
    path = _cache_file(video, config, cache)
    if path is not None and path.is_file():
        try:
            with np.load(path) as data:
                rows = np.array(data["rows"], dtype=float).reshape(-1, 10)
                stored_split = bool(data["split"])
                if split and not stored_split:
                    return None
                return BlobRows(rows, int(data["frames"]),
                                np.array(data["shapes"], dtype=float).reshape(len(rows), SHAPE_SIZE),
                                np.array(data["parts"], dtype=float).reshape(len(rows), PART_SIZE), stored_split)
        except (OSError, ValueError, KeyError):
            pass
    return None


def store_blob_detections(video: Path | str, config: BlobConfig, found: BlobRows,
                          cache: Path | None | bool = True) -> None:
    """Put ``found`` in the cache (nothing when ``cache`` is False or None, or the folder cannot be written)."""
    path = _cache_file(video, config, cache)
    if path is not None:
        buffer = io.BytesIO()
        np.savez(buffer, rows=found.rows, frames=found.frames, shapes=found.shapes, parts=found.parts,
                 split=found.split)
        _write_atomic(path, buffer.getvalue())


class BlobStream:
    """Blob detections found while the video is tracked (one decode): called on each frame in order, it gives the
    frame's boxes scoring at least ``min_score``; :meth:`found` then holds every row, as :func:`blob_detections`."""

    def __init__(self, video: Path | str, config: BlobConfig, min_score: float = -math.inf,
                 split: bool = True) -> None:
        self.detector = _detector(video, config, split)
        self.min_score, self.frames = min_score, 0
        self._rows: list[np.ndarray] = []
        self._shapes: list[np.ndarray] = []
        self._parts: list[np.ndarray] = []

    def __call__(self, image: np.ndarray) -> Detections:
        det = self.detector(image)
        self.frames += 1
        rows = detection_rows(self.frames, det.xywh, det.score)
        if len(det):
            assert det.feature is not None  # (described blobs)
            self._rows.append(rows)
            assert self.detector.parts_ is not None
            self._shapes.append(det.feature)
            self._parts.append(self.detector.parts_)
        keep = rows[:, 6] >= self.min_score
        return Detections(xywh=rows[keep, 2:6], score=rows[keep, 6])

    def shapes_at(self, index: int, boxes: np.ndarray) -> np.ndarray:
        """The shape vectors ``(k, SHAPE_SIZE)`` of the blobs with ``boxes`` ``(k, 4)`` in the 0-based frame ``index``,
        the latest read (NaN rows for boxes not found there)."""
        if self._rows and int(self._rows[-1][0, 0]) == index + 1:
            return shapes_by_box(self._rows[-1][:, 2:6], self._shapes[-1], boxes)
        return np.full((len(boxes), SHAPE_SIZE), np.nan)

    def found(self) -> BlobRows:
        """Every row found so far, the frames read and the rows' shape and parts vectors."""
        rows = np.vstack(self._rows) if self._rows else np.zeros((0, 10))
        return BlobRows(rows, self.frames, np.vstack(self._shapes) if self._shapes else np.zeros((0, SHAPE_SIZE)),
                        np.vstack(self._parts) if self._parts else np.zeros((0, PART_SIZE)), self.detector.split)


def blob_detections(video: Path | str, config: BlobConfig, advance: Callable[[], None] | None = None,
                    split: bool = True) -> BlobRows:
    """Blob detections of ``video`` (a file or image folder) with each blob's shape vector (and parts, with
    ``split``), in one pass."""
    stream = BlobStream(video, config, split=split)
    for image in source_frames(video)[0]:
        stream(image)
        if advance is not None:
            advance()
    if stream.frames == 0:
        raise ValueError(f"video: {video} has no frames")
    return stream.found()


__all__ = ["CACHE_ENV", "BlobRows", "BlobStream", "auto_blob_config", "blob_config", "blob_detections",
           "blob_settings", "cache_dir", "cached_blob_detections", "detection_cache_key", "load_blob_detections",
           "store_blob_detections"]
