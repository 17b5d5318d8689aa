"""A tracker run on a video: its detections read from a file, given as rows, or found by a detector in the same
pass; appearance features only for trackers that read them; the frames decoded once; the result and its health
and merges files written (``lookalike track --video``)."""

from __future__ import annotations

import io
import itertools
import time
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from lookalike.io import MotTable, read_mot, write_mot
from lookalike.io.det_format import box_stats, det_warnings, largest_side, read_det, sniff_det
from lookalike.io.motchallenge import format_rows
from lookalike.io.needs import input_kind
from lookalike.io.outputs import atomic_path
from lookalike.io.video_frames import source_frames, video_info
from lookalike.loop import RunStats
from lookalike.pipeline.files import dropped_all
from lookalike.pipeline.runner import Event, RunResult
from lookalike.pipeline.tracking import VideoFeatures, VideoTrackingResult, track_video
from lookalike.sim.divers_run import diver_extractor, fit_diver_features, stored_thresholds
from lookalike.trackers.parts.health import HealthConfig
from lookalike.types import Detections
from lookalike.types.mot_table import detection_rows
from lookalike.viz.video_tracking import side_file, write_health_csv, write_merges_csv

FEATURE_CHOICES = ("video", "divers", "handcrafted", "learned")
VideoDetections = Path | MotTable | Callable[[np.ndarray], Any]  # a file, rows found, or a detector run in the pass


@dataclass
class VideoInput:
    """What a tracker needs from a video before its pass: the detections ``table`` (empty when a ``detect``or runs
    in the pass), the layout ``notes`` of their file, the feature ``extractor`` (None: none computed), the frame
    ``size`` ``(w, h)`` px, the ``frames`` to decode (None: none), the declared frame count ``total`` and a
    ``name`` for the detections in messages."""

    table: MotTable
    notes: list[str]
    extractor: Any
    size: tuple[int, int] | None
    frames: Iterable[np.ndarray] | None
    total: int
    detect: Callable[[np.ndarray], Any] | None
    name: str | Path

    def warnings(self, video: Path, score_warnings: bool = True) -> list[str]:
        """Warnings on the detections: boxes outside the frame, every score equal (unless not ``score_warnings``)."""
        scores, outside = box_stats(self.table.xywh, self.table.conf, self.size)
        return det_warnings(self.name, len(self.table), scores if score_warnings else None, outside, self.size,
                            f"the frames of {video}", largest_side(self.table.xywh))

    def dropped_all(self, result: VideoTrackingResult, tracker_name: str) -> str | None:
        """The warning for a tracker that wrote no tracks from these detections, else None."""
        if not len(self.table) or len(result.rows):
            return None
        scores = box_stats(self.table.xywh, self.table.conf, None)[0]
        return dropped_all(tracker_name, self.name, len(self.table), scores)


def check_features(features: str) -> None:
    """``ValueError`` unless ``features`` is one of :data:`FEATURE_CHOICES` or an ``.onnx`` file."""
    if features not in FEATURE_CHOICES and not features.lower().endswith(".onnx"):
        raise ValueError(f"--features: choose one of {', '.join(FEATURE_CHOICES)} or FILE.onnx, got {features!r}")


def prepare_video(video: Path, detections: VideoDetections, tracker_name: str, *, annotate: Path | None = None,
                  features: str = "video", det_format: str = "auto", length: int | None = None) -> VideoInput:
    """Read ``detections`` and the feature extractor ``tracker_name`` reads (``features``: as ``--features``, ``video``
    fitted in the tracking pass); with ``length`` (the video's decoded frames) known, a
    box tracker without ``annotate`` or a detector gets no frames decoded, else the first frame gives the size and
    the frames go on to the tracker (one decode)."""
    detect = None if isinstance(detections, (Path, MotTable)) else detections
    notes: list[str] = []
    if isinstance(detections, Path):
        fmt, notes = sniff_det(detections, det_format)
        table = read_mot(detections, positive_size=True) if fmt.standard() else read_det(detections, fmt)
    else:
        table = detections if isinstance(detections, MotTable) else MotTable.from_rows(np.zeros((0, 10)))
    images, total, _ = source_frames(video)
    extractor: Any = None
    if input_kind(tracker_name) != "boxes":  # a tracker reading no appearance gets no features computed
        extractor = (fit_diver_features() if features in ("divers", "handcrafted")
                     else VideoFeatures() if features == "video" else diver_extractor(features))
    stream: Iterable[np.ndarray] | None = None
    if extractor is None and annotate is None and length is not None and detect is None:  # no frame decoded
        size = None if video.is_dir() else video_info(video)[2]
    else:  # the first frame's size; the frames go on to the tracker (one decode)
        first = next(images, None)
        size = (first.shape[1], first.shape[0]) if first is not None else None
        stream = itertools.chain([] if first is None else [first], images)
    name = detections if isinstance(detections, Path) else f"the detections in {video}"
    return VideoInput(table, notes, extractor, size, stream, total, detect, name)


def threshold_hint(extractor: Any, tracker_name: str, features: str) -> str | None:
    """A note when ``tracker_name``'s thresholds were chosen for other features than ``features``, else None."""
    hint = stored_thresholds(extractor).get(tracker_name) if extractor is not None else None
    if not hint:
        return None
    return (f"note: {tracker_name}'s thresholds were chosen for the hand-crafted features; matched to {features} on "
            "the validation divers they are " + " ".join(f"--set {k}={v:g}" for k, v in hint.items()))


def check_result_file(output: Path, video: Path | None = None) -> None:
    """``ValueError`` unless ``output`` can be a video's result file and ``video`` (if given) exists."""
    if output.is_dir():
        raise ValueError(f"-o/--output: {output} is a folder; with --video give a result file such as tracks.txt")
    if video is not None and not video.exists():
        raise ValueError(f"--video: {video} does not exist")


def run_video(video: Path, detections: VideoDetections, output: Path, tracker: Any, tracker_name: str,
              on_event: Callable[[Event], None], *, annotate: Path | None = None, team_size: int | None = None,
              health_window: int = 15, min_score: float = -np.inf, fps: float | None = None, features: str = "video",
              det_format: str = "auto", length: int | None = None, score_warnings: bool = True,
              annotate_as: Path | None = None) -> RunResult:
    """Track ``detections`` (see :func:`prepare_video`) on ``video`` with ``tracker`` (registered as
    ``tracker_name``), telling ``on_event`` (:class:`~lookalike.pipeline.runner.Event`) its notes, warnings and
    progress; write ``output``, its ``.health.csv`` (health checks of ``team_size`` over ``health_window`` frames),
    ``.merges.csv`` for merging trackers, and the ``annotate`` MP4 (told as ``annotate_as``). ``score_warnings``: False
    for a detector whose scores are all 1 by design (blobs). ``ValueError`` for a bad input, ``OSError`` for an
    output not written."""
    check_features(features)
    check_result_file(output)
    try:
        found = prepare_video(video, detections, tracker_name, annotate=annotate, features=features,
                              det_format=det_format, length=length)
    except OSError as exc:
        raise ValueError(str(exc)) from exc
    for line in found.notes:
        on_event(Event("note", f"{found.name}: {line}"))
    for line in found.warnings(video, score_warnings):
        on_event(Event("warn", line))
    hint = threshold_hint(found.extractor, tracker_name, features)
    if hint:
        on_event(Event("line", hint))
    step = f"tracking {video.name}"
    on_event(Event("start", step, found.total))
    result = track_video(video, found.table, tracker, found.extractor, annotate=annotate,
                         health=HealthConfig(team_size=team_size, window=health_window), fps=fps, min_score=min_score,
                         advance=lambda: on_event(Event("advance", step, 1)), length=length, images=found.frames,
                         detect=found.detect)
    on_event(Event("end", step))
    written = write_video_result(output, result, tracker)
    dropped = found.dropped_all(result, tracker_name)
    if dropped is not None:
        on_event(Event("warn", dropped))
    shown = [*written, *([annotate_as or annotate] if annotate is not None else [])]
    unhealthy = sum(not s.healthy for s in result.health)
    seconds = result.tracker_s + result.feature_s
    fps_text = f"{result.frames / seconds:,.0f}" if seconds > 0 else "inf"
    on_event(Event("result", f": {result.frames} frames, {len(result.merges)} merge(s), {unhealthy} frame(s) flagged "
                             f"unhealthy, {fps_text} frames/s (features + tracker) → " + ", ".join(map(str, shown)),
                       name=tracker_name))
    if result.ignored_rows:
        on_event(Event("note", f"{result.ignored_rows} detection row(s) are past the video's {result.frames} frames "
                               "and were ignored"))
    return RunResult("video", written, 1, RunStats(result.frames, result.tracker_s), result)


def write_video_result(output: Path, result: VideoTrackingResult, tracker: Any) -> list[Path]:
    """``output`` (MOTChallenge rows), its ``.health.csv`` and, for a merging tracker, its ``.merges.csv``, each
    appearing whole; returns the files written."""
    write_mot(output, result.rows)
    written = [output, side_file(output, "health")]
    with atomic_path(written[1]) as tmp:
        write_health_csv(tmp, result.health)
    if hasattr(tracker, "merges"):
        written.append(side_file(output, "merges"))
        with atomic_path(written[-1]) as tmp:
            write_merges_csv(tmp, result.merges)
    return written


def as_written(rows: np.ndarray) -> np.ndarray:
    """Detection rows ``(n, 10)`` as they read back from a MOTChallenge file (:func:`~lookalike.io.write_mot`)."""
    return np.loadtxt(io.StringIO(format_rows(rows)), delimiter=",", ndmin=2).reshape(-1, 10)


class OnnxStream:
    """An ONNX ``detector`` run in the tracking pass (one decode): called on each frame in order, it gives the
    frame's boxes scoring at least ``min_score``, as a saved detection file holds them (:func:`as_written`);
    :meth:`found` then holds every row, the frames read and the detector's seconds."""

    def __init__(self, detector: Any, min_score: float = -np.inf) -> None:
        self.detector, self.min_score, self.frames, self.seconds = detector, min_score, 0, 0.0
        self._rows: list[np.ndarray] = []

    def __call__(self, image: np.ndarray) -> Detections:
        t0 = time.perf_counter()
        det = self.detector(image)
        self.frames += 1
        rows = as_written(detection_rows(self.frames, det.xywh, det.score)) if len(det) else np.zeros((0, 10))
        self._rows.append(rows)
        self.seconds += time.perf_counter() - t0
        keep = rows[:, 6] >= self.min_score
        return Detections(xywh=rows[keep, 2:6], score=rows[keep, 6])

    def found(self) -> tuple[np.ndarray, int, float]:
        """Every row found so far ``(n, 10)``, the frames read and the detector's seconds."""
        return np.vstack(self._rows) if self._rows else np.zeros((0, 10)), self.frames, self.seconds


@dataclass
class OnnxRun:
    """An ONNX ``detector`` (:class:`lookalike.vision.onnx_detector.OnnxDetector`) opened on a video's ``images``
    (``total`` frames, 0: unknown; ``rate``: its frame rate, frames/s)."""

    detector: Any
    images: Iterable[np.ndarray]
    total: int
    rate: float

    def detect(self, advance: Callable[[], None] | None = None) -> tuple[np.ndarray, int, float]:
        """The detection rows found in every frame (as :func:`lookalike.vision.onnx_detector.detect_frames`), the
        frames read and the seconds it took; ``advance`` after each frame."""
        from lookalike.vision.onnx_detector import detect_frames

        t0 = time.perf_counter()
        rows, frames = detect_frames(self.images, self.detector, advance=advance)
        return rows, frames, time.perf_counter() - t0

    def in_pass(self, tracker_name: str, annotate: bool, offline: bool, min_score: float) -> OnnxStream | None:
        """The detector run in the tracking pass when that pass decodes the frames anyway (``annotate``, or a
        tracker reading appearance features), never ``offline``; else None (the frames are detected first)."""
        if offline or not (annotate or input_kind(tracker_name) != "boxes"):
            return None
        return OnnxStream(self.detector, min_score)


def open_onnx(video: Path, model: Path, settings: list[str]) -> OnnxRun:
    """The ONNX ``model`` (``settings``: its ``KEY=VALUE``) opened on ``video``; ``ValueError`` naming ``--detector``
    when the model is missing, ``ValueError``/``OSError`` for a bad model or video."""
    from lookalike.vision.onnx_detector import OnnxDetector, config_from_settings

    if not model.is_file():
        raise ValueError(f"--detector: {model} does not exist")
    detector = OnnxDetector(model, config_from_settings(settings))
    images, total, rate = source_frames(video)
    return OnnxRun(detector, images, total, rate)


def run_onnx(video: Path, output: Path, tracker: Any, tracker_name: str, model: Path, settings: list[str],
             on_event: Callable[[Event], None], *, n_targets: int | None = None, offline: dict[str, Any] | None = None,
             save_detections: Path | None = None, **options: Any) -> RunResult:
    """``track --video V --detector FILE.onnx``: detect with the ONNX ``model`` (``settings``: ``KEY=VALUE``; the
    boxes written to ``save_detections`` when given), then track as :func:`run_video` (given ``options``; detected in
    the tracking pass when it decodes the frames anyway) or, with ``offline`` (the online pass's parameters), by
    the offline closed set of ``n_targets``. What it does is told to ``on_event``; ``ValueError`` for a bad input."""
    from lookalike.pipeline.closed import offline_video

    check_result_file(output, video)
    try:
        run = open_onnx(video, model, settings)
    except OSError as exc:
        raise ValueError(str(exc)) from exc
    stream = run.in_pass(tracker_name, options.get("annotate") is not None, offline is not None, options["min_score"])
    result = RunResult("blobs", [output], 1)
    if stream is not None:
        result = run_video(video, stream, output, tracker, tracker_name, on_event, **options)
        rows, frames, seconds = stream.found()
    else:
        name = f"detecting {video.name}"
        on_event(Event("start", name, run.total))
        try:
            rows, frames, seconds = run.detect(advance=lambda: on_event(Event("advance", name, 1)))
        except OSError as exc:
            raise ValueError(str(exc)) from exc
        on_event(Event("end", name))
    speed = f"{frames / seconds:,.1f} frames/s" if seconds > 0 else "inf frames/s"
    width, height = run.detector.input_size
    saved = "" if save_detections is None else f" → {write_mot(save_detections, rows)}"
    on_event(Event("line", f"{model.name} ({run.detector.layout}, input {width}x{height}): {len(rows)} boxes in "
                           f"{frames} frames, {speed}{saved}"))
    if len(rows) < 2:
        raise ValueError(f"{video}: the detector {model.name} found {len(rows)} box(es); try a lower score=... setting")
    if stream is not None:
        return result
    rows = as_written(rows)  # (tracked as a saved detection file would be: boxes to 1/1000 px, scores to 6 digits)
    if offline is not None:
        assert n_targets is not None
        offline_video(rows, output, n_targets, offline, float(options.get("fps") or run.rate), frames,
                      options["min_score"], on_event, video=video, annotate=options.get("annotate"),
                      annotate_as=options.get("annotate_as"))
        return result
    return run_video(video, MotTable.from_rows(rows), output, tracker, tracker_name, on_event, length=frames,
                     **options)


__all__ = ["FEATURE_CHOICES", "OnnxRun", "OnnxStream", "VideoDetections", "VideoInput", "as_written", "check_features",
           "check_result_file", "open_onnx", "prepare_video", "run_onnx", "run_video", "threshold_hint",
           "write_video_result"]
