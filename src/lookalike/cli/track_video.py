"""The ``--video`` branch of ``lookalike track``: features from the frames' pixels, tracks, merges, detector
health, optional annotated video."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
from rich.markup import escape

from lookalike.cli.app import console, fail, failing, note, warn
from lookalike.cli.progress import bars
from lookalike.cli.track_closed import check_result_file, offline_video
from lookalike.io import MotTable, write_mot
from lookalike.pipeline.tracking import track_video
from lookalike.pipeline.video import (
    VideoDetections,
    as_written,
    check_features,
    open_onnx,
    prepare_video,
    threshold_hint,
    write_video_result,
)
from lookalike.trackers.parts.health import HealthConfig

__all__ = ["run_track_onnx", "run_track_video", "save_detections"]


def run_track_video(video: Path, detections: VideoDetections, output: Path, tracker: Any, tracker_name: str, *,
                    annotate: Path | None, team_size: int | None, health_window: int,
                    min_score: float, fps: float | None, features: str = "video",
                    annotate_as: Path | None = None, det_format: str = "auto", length: int | None = None,
                    score_warnings: bool = True) -> None:
    """Track ``detections`` (a file, the rows a detector found, or a detector run in the same pass) on ``video``;
    write ``output``, its ``.health.csv`` (``.merges.csv`` for merging trackers) and, with ``annotate``, the annotated
    MP4 (printed as ``annotate_as``); see :func:`lookalike.pipeline.video.prepare_video`. ``score_warnings``: False
    for a detector whose scores are all 1 by design (blobs)."""
    with failing(ValueError):
        check_features(features)
    check_result_file(output)
    with failing(ValueError, OSError):
        found = prepare_video(video, detections, tracker_name, annotate=annotate, features=features,
                              det_format=det_format, length=length, status=console.status)
    for line in found.notes:
        note(f"{found.name}: {line}")
    for line in found.warnings(video, score_warnings):
        warn(line)
    hint = threshold_hint(found.extractor, tracker_name, features)
    if hint:
        console.print(hint, markup=False)
    try:
        with bars("tracking {task.description}") as progress:
            task = progress.add_task(video.name, total=found.total or None)
            result = track_video(video, found.table, tracker, found.extractor, annotate=annotate,
                                 health=HealthConfig(team_size=team_size, window=health_window), fps=fps,
                                 min_score=min_score, advance=lambda: progress.advance(task), length=length,
                                 images=found.frames, detect=found.detect)
    except ValueError as exc:
        fail(str(exc))
    except KeyboardInterrupt:
        console.print("\n[yellow]Interrupted.[/] Nothing was written"
                      + (f" ({escape(str(annotate_as or annotate))} is left as it was)." if annotate else "."))
        raise SystemExit(130) from None
    written = write_video_result(output, result, tracker)
    dropped = found.dropped_all(result, tracker_name)
    if dropped is not None:
        warn(dropped)
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
    saved to ``options["save_detections"]`` when given), then track as :func:`run_track_video` (given ``options``;
    detected in the tracking pass when it decodes the frames anyway) or, with ``offline``, by the offline closed set
    of ``n_targets``."""
    check_result_file(output, video)
    with failing(ValueError, OSError):
        run = open_onnx(video, model, settings)
        stream = run.in_pass(tracker_name, options.get("annotate") is not None, offline is not None,
                             options["min_score"])
        saved = {"save_detections": options.pop("save_detections", None)}
        if stream is not None:
            run_track_video(video, stream, output, tracker, tracker_name, **options)
            rows, frames, seconds = stream.found()
        else:
            with bars("detecting {task.description}") as progress:
                task = progress.add_task(video.name, total=run.total or None)
                rows, frames, seconds = run.detect(advance=lambda: progress.advance(task))
    speed = f"{frames / seconds:,.1f} frames/s" if seconds > 0 else "inf frames/s"
    width, height = run.detector.input_size
    console.print(f"{model.name} ({run.detector.layout}, input {width}x{height}): "
                  f"{len(rows)} boxes in {frames} frames, {speed}" + save_detections(rows, saved))
    if len(rows) < 2:
        fail(f"{video}: the detector {model.name} found {len(rows)} box(es); try a lower score=... setting")
    if stream is not None:
        return
    rows = as_written(rows)  # (tracked as a saved detection file would be: boxes to 1/1000 px, scores to 6 digits)
    if offline is not None:
        assert n_targets is not None
        offline_video(rows, output, n_targets, offline, float(options.get("fps") or run.rate), frames,
                      options["min_score"])
    else:
        run_track_video(video, MotTable.from_rows(rows), output, tracker, tracker_name, length=frames, **options)


def save_detections(rows: np.ndarray, options: dict[str, Any]) -> str:
    """Write ``rows`` to ``options["save_detections"]`` (popped; ``--save-detections``) when given: `` → PATH`` for
    the printed line, else ``""``."""
    path = options.pop("save_detections", None)
    return "" if path is None else f" → {write_mot(path, rows)}"
