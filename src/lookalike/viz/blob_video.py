"""Blob detections of a whole video as MOTChallenge rows (``lookalike track --video V --detector blob``).

The video is read twice: once to fit the median background on ``history`` frames spread evenly over
it (the ``median`` method; ``mog2`` learns online and skips this pass), once to detect.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

from lookalike.vision.blob import BlobConfig, BlobDetector
from lookalike.viz.overlay import source_frames

_BOOL_TRUE = ("1", "true", "yes", "on")
_BOOL_FALSE = ("0", "false", "no", "off")


def blob_config(settings: list[str]) -> BlobConfig:
    """A :class:`BlobConfig` from ``KEY=VALUE`` strings (keys are its field names, e.g. ``threshold=40``,
    ``polarity=dark``, ``min_area_px=50``); an unknown key or a bad value raises ``ValueError`` naming it."""
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
    return BlobConfig(**values)


def blob_detection_rows(video: Path | str, config: BlobConfig,
                        advance: Callable[[], None] | None = None) -> tuple[np.ndarray, int]:
    """Blob detections of every frame of ``video`` (a file or an image folder) as MOTChallenge rows
    ``(n, 10)`` (1-based frames, id -1, box in pixels, score), and the number of frames read."""
    detector = BlobDetector(config)
    if config.method == "median":
        frames, declared, _ = source_frames(video)
        picked = _background_sample(frames, declared, config.history)
        if not picked:
            raise ValueError(f"video: {video} has no frames")
        detector.fit(picked)
    frames, _, _ = source_frames(video)
    rows: list[np.ndarray] = []
    count = 0
    for k, image in enumerate(frames):
        det = detector(image)
        if len(det):
            block = np.full((len(det), 10), -1.0)
            block[:, 0] = k + 1
            block[:, 2:6] = det.xywh
            block[:, 6] = det.score
            rows.append(block)
        count += 1
        if advance is not None:
            advance()
    if count == 0:
        raise ValueError(f"video: {video} has no frames")
    return (np.vstack(rows) if rows else np.zeros((0, 10))), count


def _background_sample(frames: Any, declared: int, count: int) -> list[np.ndarray]:
    """Up to ``count`` frames spread evenly over the video (all of them when its length is unknown and short)."""
    if declared > 0:
        wanted = set(np.linspace(0, declared - 1, min(declared, count)).round().astype(int).tolist())
        return [img for k, img in enumerate(frames) if k in wanted]
    every = list(frames)  # length unknown: keep the frames, then subsample
    pick: Any = np.unique(np.linspace(0, len(every) - 1, min(len(every), count)).round().astype(int)) if every else []
    return [every[k] for k in pick]


__all__ = ["blob_config", "blob_detection_rows"]
