"""The ``--video`` branch of ``lookalike track``: features from the frames' pixels, tracks, merges, detector
health, optional annotated video."""

from __future__ import annotations

import io
import itertools
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
from rich.markup import escape

from lookalike.cli.app import console, fail, failing, note, warn
from lookalike.cli.progress import bars
from lookalike.cli.track import dropped_all
from lookalike.cli.track_closed import check_result_file, offline_video
from lookalike.io import MotTable, read_mot, write_mot
from lookalike.io.det_format import box_stats, det_warnings, read_det, sniff_det
from lookalike.io.motchallenge import format_rows
from lookalike.io.needs import input_kind
from lookalike.io.outputs import atomic_path
from lookalike.sim.divers_run import diver_extractor, fit_diver_features, stored_thresholds
from lookalike.trackers.parts.health import HealthConfig
from lookalike.viz.overlay import source_frames
from lookalike.viz.video import video_info
from lookalike.viz.video_tracking import fit_video_features, side_file, track_video, write_health_csv, write_merges_csv

FEATURE_CHOICES = ("video", "divers", "handcrafted", "learned")


def run_track_video(video: Path, detections: Path | MotTable | Callable[[np.ndarray], Any], output: Path,
                    tracker: Any, tracker_name: str, *,
                    annotate: Path | None, team_size: int | None, health_window: int,
                    min_score: float, fps: float | None, features: str = "video",
                    annotate_as: Path | None = None, det_format: str = "auto", length: int | None = None,
                    score_warnings: bool = True) -> None:
    """Track ``detections`` (a file, the rows a detector found, or a detector run in the same pass) on ``video``;
    write ``output``, its ``.health.csv`` (``.merges.csv`` for merging trackers) and, with ``annotate``, the annotated
    MP4 (printed as ``annotate_as``). ``features``: ``video``, ``divers``/``handcrafted``, ``learned`` or
    ``FILE.onnx`` (the ``--features`` option). ``length``: the video's decoded frames when known (then a box
    tracker without ``annotate`` decodes none); ``score_warnings``: False for a detector whose scores are all 1 by
    design (blobs)."""
    if features not in FEATURE_CHOICES and not features.lower().endswith(".onnx"):
        fail(f"--features: choose one of {', '.join(FEATURE_CHOICES)} or FILE.onnx, got {features!r}")
    check_result_file(output)
    detect = None if isinstance(detections, (Path, MotTable)) else detections
    with failing(ValueError, OSError):
        if not isinstance(detections, Path):
            table = detections if isinstance(detections, MotTable) else MotTable.from_rows(np.zeros((0, 10)))
            notes: list[str] = []
        else:
            fmt, notes = sniff_det(detections, det_format)
            table = read_mot(detections) if fmt.standard() else read_det(detections, fmt)
        health = HealthConfig(team_size=team_size, window=health_window)
        images, total, _ = source_frames(video)
        if input_kind(tracker_name) == "boxes":  # reads no appearance: no features computed
            extractor: Any = None
        else:
            with console.status("standardising appearance features"):
                extractor = (fit_diver_features() if features in ("divers", "handcrafted")
                             else fit_video_features(video, table, min_score=min_score) if features == "video"
                             else diver_extractor(features))
        stream: Any = None
        if extractor is None and annotate is None and length is not None and detect is None:  # no frame decoded
            size = None if video.is_dir() else video_info(video)[2]
        else:  # the first frame's size; the frames go on to the tracker (one decode)
            first = next(images, None)
            size = (first.shape[1], first.shape[0]) if first is not None else None
            stream = itertools.chain([] if first is None else [first], images)
    name = f"the detections in {video}" if not isinstance(detections, Path) else detections
    for line in notes:
        note(f"{name}: {line}")
    scores, outside = box_stats(table.xywh, table.conf, size)
    for line in det_warnings(name, len(table), scores if score_warnings else None, outside, size,
                             f"the frames of {video}"):
        warn(line)
    hint = stored_thresholds(extractor).get(tracker_name) if extractor is not None else None
    if hint:
        console.print(f"note: {tracker_name}'s thresholds were chosen for the hand-crafted features; matched to "
                      f"{features} on the validation divers they are "
                      + " ".join(f"--set {k}={v:g}" for k, v in hint.items()), markup=False)
    try:
        with bars("tracking {task.description}") as progress:
            task = progress.add_task(video.name, total=total or None)
            result = track_video(video, table, tracker, extractor, annotate=annotate, health=health,
                                 fps=fps, min_score=min_score, advance=lambda: progress.advance(task), length=length,
                                 images=stream, detect=detect)
    except ValueError as exc:
        fail(str(exc))
    except KeyboardInterrupt:
        console.print("\n[yellow]Interrupted.[/] Nothing was written"
                      + (f" ({escape(str(annotate_as or annotate))} is left as it was)." if annotate else "."))
        raise SystemExit(130) from None
    write_mot(output, result.rows)
    if len(table) and not len(result.rows):
        warn(dropped_all(tracker_name, name, len(table), scores))
    written = [output, side_file(output, "health")]
    with atomic_path(written[1]) as tmp:  # (the side files too appear whole, through temporary files)
        write_health_csv(tmp, result.health)
    if hasattr(tracker, "merges"):
        written.append(side_file(output, "merges"))
        with atomic_path(written[-1]) as tmp:
            write_merges_csv(tmp, result.merges)
    if annotate is not None:
        written.append(annotate_as or annotate)
    unhealthy = sum(not s.healthy for s in result.health)
    seconds = result.tracker_s + result.feature_s
    fps_text = f"{result.frames / seconds:,.0f}" if seconds > 0 else "inf"
    console.print(f"[green]{tracker_name}[/]: {result.frames} frames, {len(result.merges)} merge(s), {unhealthy} "
                  f"frame(s) flagged unhealthy, {fps_text} frames/s (features + tracker) → "
                  + escape(", ".join(str(p) for p in written)))
    if result.ignored_rows:
        console.print(f"[yellow]note:[/] {result.ignored_rows} detection row(s) are past the video's "
                      f"{result.frames} frames and were ignored")


def run_track_onnx(video: Path, output: Path, tracker: Any, tracker_name: str, model: Path, settings: list[str], *,
                   n_targets: int | None = None, offline: dict[str, Any] | None = None, **options: Any) -> None:
    """``track --video V --detector FILE.onnx``: detect with the ONNX model (``settings``: ``KEY=VALUE``; the boxes
    saved to ``options["save_detections"]`` when given), then track as :func:`run_track_video` (given ``options``)
    or, with ``offline``, by the offline closed set of ``n_targets``."""
    import time

    from lookalike.vision.onnx_detector import OnnxDetector, config_from_settings, detect_frames

    check_result_file(output, video)
    if not model.is_file():
        fail(f"--detector: {model} does not exist")
    with failing(ValueError, OSError):
        detector = OnnxDetector(model, config_from_settings(settings))
        images, total, rate = source_frames(video)
        with bars("detecting {task.description}") as progress:
            task = progress.add_task(video.name, total=total or None)
            t0 = time.perf_counter()
            rows, frames = detect_frames(images, detector, advance=lambda: progress.advance(task))
            seconds = time.perf_counter() - t0
    speed = f"{frames / seconds:,.1f} frames/s" if seconds > 0 else "inf frames/s"
    console.print(f"{model.name} ({detector.layout}, input {detector.input_size[0]}x{detector.input_size[1]}): "
                  f"{len(rows)} boxes in {frames} frames, {speed}" + save_detections(rows, options))
    if len(rows) < 2:
        fail(f"{video}: the detector {model.name} found {len(rows)} box(es); try a lower score=... setting")
    rows = as_written(rows)  # (tracked as a saved detection file would be: boxes to 1/1000 px, scores to 6 digits)
    if offline is not None:
        assert n_targets is not None
        offline_video(rows, output, n_targets, offline, float(options.get("fps") or rate), frames,
                      options["min_score"])
    else:
        run_track_video(video, MotTable.from_rows(rows), output, tracker, tracker_name, length=frames, **options)


def as_written(rows: np.ndarray) -> np.ndarray:
    """Detection rows ``(n, 10)`` as they read back from a MOTChallenge file (:func:`~lookalike.io.write_mot`)."""
    return np.loadtxt(io.StringIO(format_rows(rows)), delimiter=",", ndmin=2).reshape(-1, 10)


def save_detections(rows: np.ndarray, options: dict[str, Any]) -> str:
    """Write ``rows`` to ``options["save_detections"]`` (popped; ``--save-detections``) when given: `` → PATH`` for
    the printed line, else ``""``."""
    path = options.pop("save_detections", None)
    return "" if path is None else f" → {write_mot(path, rows)}"
