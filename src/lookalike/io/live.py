"""Tracking a live source (a camera, a stream, :mod:`lookalike.io.sources`) into a MOTChallenge result file: blob
settings from the first frames or an ONNX detector, one frame at a time, frames skipped when the tracker falls behind,
and a stop on a signal, a frame count or a duration that still leaves a whole result file."""

from __future__ import annotations

import dataclasses
import time
from collections.abc import Callable, Collection, Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from lookalike.io.sources import LiveFrame, LiveSource, SignalStop
from lookalike.io.stream import MotWriter
from lookalike.trackers.offline.online_look import LookIdentities
from lookalike.types import Detections, Frame
from lookalike.types.mot_table import tracks_to_rows
from lookalike.vision.blob import BlobConfig, BlobDetector
from lookalike.vision.blob_auto import BlobEstimate, TargetCount, estimate_blob_config
from lookalike.vision.blob_boxtrack import blob_boxtrack_config

__all__ = ["LivePlan", "LiveRun", "LiveStop", "SAMPLE_FRAMES", "SAMPLE_S", "live_blob_detector", "prepare_live",
           "sample_frames", "track_live"]

SAMPLE_S = 2.0
"""Seconds of a live source's first frames that set the blob detector (its settings and median background)."""
SAMPLE_FRAMES = 50
"""At most this many frames in that sample (memory: 50 frames of 1080p are 300 MB)."""
_WAIT_S = 0.5  # seconds between looks at the stop while a stalled source sends nothing


class LiveStop(SignalStop):
    """:class:`~lookalike.io.sources.SignalStop` for a live run: a second Ctrl-C interrupts at once."""

    def __init__(self) -> None:
        super().__init__(interrupt_twice=True)


@dataclass
class LiveRun:
    """What one :func:`track_live` did. ``frames``: tracked; ``delivered``/``dropped``: frames the source gave and
    those skipped because the tracker was busy (``dropped_before`` of them before tracking began, while the
    detector was set up); ``rows``: result rows written; ``wall_s``: seconds from the first
    frame to the stop; ``busy_s``: seconds in the detector and the tracker; ``clock``: where frame times came from
    (``stream`` or ``wall clock``); ``stopped``: why the run ended."""

    frames: int = 0
    delivered: int = 0
    dropped: int = 0
    dropped_before: int = 0
    rows: int = 0
    wall_s: float = 0.0
    busy_s: float = 0.0
    clock: str = "wall clock"
    stopped: str = "end of stream"
    output: Path | None = None
    notes: list[str] = field(default_factory=list)

    @property
    def fps(self) -> float:
        """Frames tracked per wall second (0 before the second frame)."""
        return self.frames / self.wall_s if self.wall_s > 0 else 0.0

    @property
    def busy_fps(self) -> float:
        """Frames per second the detector and tracker could take (inf when unmeasured)."""
        return self.frames / self.busy_s if self.busy_s > 0 else float("inf")


@dataclass
class LivePlan:
    """A live run set up by :func:`prepare_live`: the ``detector`` and ``tracker`` to run, the ``sample`` frames
    read already with their ``sampled`` detections, and for blobs the settings' ``estimate`` and the ``count`` of
    targets inferred from the sample (each None when not made)."""

    detector: Callable[[Any], Detections]
    tracker: Any
    sample: list[LiveFrame] = field(default_factory=list)
    sampled: list[Detections] = field(default_factory=list)
    estimate: BlobEstimate | None = None
    count: TargetCount | None = None
    n_targets: int | None = None


def sample_frames(source: LiveSource, seconds: float = SAMPLE_S, count: int = SAMPLE_FRAMES,
                  stop: SignalStop | None = None) -> list[LiveFrame]:
    """The source's first frames: those of its first ``seconds`` (stream time), at most ``count``; fewer when the
    source ends or ``stop`` is set."""
    frames: list[LiveFrame] = []
    for frame in _arriving(source, stop):
        frames.append(frame)
        if len(frames) >= count or frame.time >= seconds or stop:
            break
    return frames


def live_blob_detector(sample: list[LiveFrame], given: dict[str, Any], n_targets: int | None = None,
                       ) -> tuple[BlobDetector, BlobEstimate | None]:
    """A blob detector set on ``sample`` (the first frames): settings estimated as for a file
    (:func:`~lookalike.vision.blob_auto.estimate_blob_config`; skipped when ``given`` holds threshold, polarity and
    both areas), ``given`` (typed :class:`BlobConfig` fields) on top, and for the ``median`` method the background
    fitted on the sample; and the estimate or None. ``ValueError`` for an empty sample."""
    images = [f.image for f in sample]
    if not images:
        raise ValueError("video: the live source sent no frame")
    estimate = None
    if {"threshold", "polarity", "min_area_px", "max_area_px"} <= set(given):
        config = BlobConfig(**given)
    else:
        base = BlobConfig(**{k: v for k, v in given.items() if k in ("method", "blur_px", "history", "sample_every")})
        estimate = estimate_blob_config(images, n_targets, base=base)
        config = dataclasses.replace(estimate.config, **given)
    detector = BlobDetector(config)
    if config.method == "median":
        detector.fit(images)
    return detector, estimate


def _arriving(source: LiveSource, stop: SignalStop | None) -> Iterator[LiveFrame]:
    """The source's frames as they come, until it ends or ``stop`` is set (looked at every :data:`_WAIT_S` s while
    the source sends nothing)."""
    while not stop:
        live = source.next(timeout=_WAIT_S)
        if live is not None:
            yield live
        elif source.ended:
            return


def _frames(source: LiveSource, detector: Callable[[Any], Detections], sample: list[LiveFrame],
            sampled: list[Detections], stop: SignalStop) -> Iterator[tuple[Frame, float]]:
    """The tracker's frames: the sample's (detected already; the lists are emptied once tracked, freeing the
    images), then the source's as they come (:func:`_arriving`); with the seconds spent detecting each."""
    for live, det in zip(sample, sampled):
        yield Frame(index=live.number, time=live.time, detections=det), 0.0
    sample.clear()
    sampled.clear()
    for live in _arriving(source, stop):
        t0 = time.perf_counter()
        det = detector(live.image)
        yield Frame(index=live.number, time=live.time, detections=det), time.perf_counter() - t0


def track_live(source: LiveSource, plan: LivePlan, output: str | Path, *, max_frames: int | None = None,
               seconds: float | None = None, stop: SignalStop | None = None,
               on_frame: Callable[[LiveRun], None] | None = None) -> LiveRun:
    """Detect and track ``source`` frame by frame with ``plan``'s detector and tracker (:func:`prepare_live`, or a
    :class:`LivePlan` of your own) into the MOTChallenge file ``output`` (frame numbers: the source's, 1-based, so a
    dropped frame leaves a gap), until the source ends, ``max_frames`` are tracked, ``seconds`` of
    stream time have passed, or ``stop`` is set (or ``KeyboardInterrupt``). Rows reach a temporary file beside
    ``output`` as each frame ends; whatever stops the run, the file is completed up to the last whole frame and
    renamed onto ``output`` (a ``KeyboardInterrupt`` ends the run like ``stop``; a ``SystemExit`` is raised again
    once the file is complete; an error of the detector or tracker ends it, told in ``stopped``). The plan's sample
    frames, read and detected already, are tracked first, then emptied from the plan.
    ``on_frame``: called with the running totals after each frame."""
    stop = stop if stop is not None else LiveStop()
    run = LiveRun(output=Path(output))
    start = time.monotonic()
    run.dropped_before = source.dropped
    exiting: SystemExit | None = None
    with MotWriter(output) as writer:
        try:
            for frame, detect_s in _frames(source, plan.detector, plan.sample, plan.sampled, stop):
                t0 = time.perf_counter()
                tracks = plan.tracker.update(frame)
                rows = tracks_to_rows(frame.index, tracks)
                run.busy_s += detect_s + time.perf_counter() - t0
                writer.write_rows(rows)
                writer.flush()
                run.frames += 1
                run.rows = writer.rows
                run.wall_s = time.monotonic() - start
                if on_frame is not None:
                    on_frame(run)
                if max_frames is not None and run.frames >= max_frames:
                    run.stopped = f"{max_frames} frames"
                    break
                if seconds is not None and frame.time >= seconds:
                    run.stopped = f"{seconds:g} s"
                    break
                if stop:
                    run.stopped = stop.reason or "stopped"
                    break
        except KeyboardInterrupt:
            run.stopped = "KeyboardInterrupt"
        except SystemExit as exc:  # SIGTERM through the command line's handler
            run.stopped, exiting = f"exit {exc.code}", exc
        except Exception as exc:  # noqa: BLE001 (a frame the detector or tracker refuses, e.g. of another size)
            run.stopped = f"error: {exc}"
        finally:
            if stop and run.stopped == "end of stream":  # set while the source sent nothing
                run.stopped = stop.reason or "stopped"
            elif source.error is not None and run.stopped == "end of stream":
                run.stopped = f"source error: {source.error}"
            run.wall_s = time.monotonic() - start
            run.delivered, run.dropped, run.clock = source.delivered, source.dropped, source.clock
    if exiting is not None:
        raise exiting
    return run


def prepare_live(source: LiveSource, detector: str, tracker: Any, tracker_name: str, *,
                 blob: dict[str, Any] | None = None, onnx: list[str] | None = None, n_targets: int | None = None,
                 explicit: Collection[str] = (), min_score: float = -np.inf, stop: SignalStop | None = None,
                 sample_s: float = SAMPLE_S) -> LivePlan:
    """Set a live run up. ``detector``: ``blob`` (settings from the first ``sample_s`` seconds of ``source`` and
    ``blob``, typed :class:`BlobConfig` fields, on top; ``boxtrack`` gets the blob rules of
    :func:`~lookalike.vision.blob_boxtrack.blob_boxtrack_config`, the number of targets when not given inferred from
    the sample; ``n_targets=0``: an open set) or an ONNX model file (``onnx``: its ``KEY=VALUE`` settings).
    Detections scoring below ``min_score`` are dropped. ``ValueError`` for a source without frames or bad settings."""
    if detector.lower().endswith(".onnx"):
        from lookalike.vision.onnx_detector import OnnxDetector, config_from_settings

        model = OnnxDetector(Path(detector), config_from_settings(onnx or []))
        return LivePlan(_min_score(model, min_score), tracker, n_targets=n_targets or None)
    sample = sample_frames(source, sample_s, stop=stop)
    try:
        blobs, estimate = live_blob_detector(sample, blob or {}, n_targets or None)
    except ValueError as exc:
        cut = _sample_cut(source, sample, sample_s, stop)
        if not cut:
            raise
        raise ValueError(f"video: {cut} after {len(sample)} frame(s) of the first {sample_s:g} s, before the blob "
                         f"detector was set ({exc}); nothing tracked") from exc
    find = _min_score(blobs, min_score)
    sampled = [find(f.image) for f in sample]
    plan = LivePlan(find, tracker, sample, sampled, estimate, n_targets=n_targets or None)
    if tracker_name == "boxtrack":
        counts = np.array([len(d) for d in sampled], dtype=int)
        boxes = blob_boxtrack_config(tracker.config, counts, explicit, n_targets)
        plan.count, plan.n_targets = boxes.count, boxes.n_targets
        if boxes.config != tracker.config:
            plan.tracker = type(tracker)(boxes.config)
        if plan.n_targets:  # the slots re-assigned by the look learned from the frames after the sample
            blobs.describe, blobs.split = True, False
            plan.tracker = LookIdentities(plan.tracker, plan.n_targets, _frame_rate(source, sample))
    return plan


def _sample_cut(source: LiveSource, sample: list[LiveFrame], seconds: float, stop: SignalStop | None) -> str:
    """What ended ``sample`` before its ``seconds`` (s) or :data:`SAMPLE_FRAMES` frames: the stop, an error or the
    end of the source; '' when it is whole."""
    if len(sample) >= SAMPLE_FRAMES or (sample and sample[-1].time >= seconds):
        return ""
    if stop:
        return f"stopped ({stop.reason or 'stop'})"
    if source.error is not None:
        return f"the source failed ({source.error})"
    return "the source ended" if source.ended else ""


def _frame_rate(source: LiveSource, sample: list[LiveFrame]) -> float:
    """The source's frames per second: as it declares, else from the sample's times (25 when they say nothing)."""
    if source.frame_rate:
        return float(source.frame_rate)
    span = sample[-1].time - sample[0].time if len(sample) > 1 else 0.0
    return (len(sample) - 1) / span if span > 0 else 25.0


def _min_score(detector: Callable[[Any], Detections], min_score: float) -> Callable[[Any], Detections]:
    """``detector`` keeping only the detections scoring ``min_score`` or more."""
    if not np.isfinite(min_score):
        return detector

    def kept(image: Any) -> Detections:
        det = detector(image)
        return det.select(np.flatnonzero(det.score >= min_score)) if len(det) and det.score is not None else det

    return kept
