"""``lookalike track --video FILE --detector blob``: detections from the blob detector instead of a det.txt.

The video is read twice: once to fit the median background on ``history`` frames spread evenly over
it (the ``median`` method; ``mog2`` learns online and skips this pass), once to detect. The blob
boxes are written as a MOTChallenge detection file ``<output stem>.det.txt`` beside the result, and
that file feeds the ordinary ``--video`` branch (:func:`~lookalike.cli.track_video.run_track_video`):
any registered tracker, health monitor, optional annotated video. Not a command of its own.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

from lookalike.cli.app import console, fail
from lookalike.cli.track_video import run_track_video
from lookalike.io import write_mot
from lookalike.vision.blob import BlobConfig, BlobDetector
from lookalike.viz.overlay import source_frames

DETECTORS = ("blob",)
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
    pick = np.unique(np.linspace(0, len(every) - 1, min(len(every), count)).round().astype(int)) if every else []
    return [every[k] for k in pick]


def run_track_blobs(video: Path, output: Path, tracker: Any, tracker_name: str, detector: str,
                    settings: list[str], **options: Any) -> None:
    """Detect blobs on ``video``, write them to ``<output stem>.det.txt``, then track them as
    :func:`~lookalike.cli.track_video.run_track_video` does (``options`` are passed on to it)."""
    if detector not in DETECTORS:
        fail(f"--detector: choose one of {', '.join(DETECTORS)}, got {detector!r}")
    if output.is_dir():
        fail(f"-o/--output: {output} is a folder; with --video give a result file such as tracks.txt")
    if not video.exists():
        fail(f"--video: {video} does not exist")
    try:
        config = blob_config(settings)
        with console.status(f"detecting blobs in {video.name}"):
            rows, frames = blob_detection_rows(video, config)
    except (ValueError, OSError) as exc:
        fail(str(exc))
    det_path = write_mot(output.with_name(output.stem + ".det.txt"), rows)
    console.print(f"blob detector: {len(rows)} boxes in {frames} frames → {det_path}")
    if len(rows) < 2:
        fail(f"{video}: the blob detector found {len(rows)} box(es); try a lower --blob threshold=... "
             "or min_area_px=..., or polarity=dark/bright")
    run_track_video(video, det_path, output, tracker, tracker_name, **options)
