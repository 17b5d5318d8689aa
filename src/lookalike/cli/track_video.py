"""``lookalike track --video``: the video branch of ``lookalike track`` (features from the frames'
pixels, tracks, merges, detector health, optional annotated video). Not a command of its own."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from rich.progress import (
    BarColumn,
    MofNCompleteColumn,
    Progress,
    TextColumn,
    TimeElapsedColumn,
)

from lookalike.cli.app import console, fail
from lookalike.io import read_mot, write_mot
from lookalike.sim.divers_run import fit_diver_features
from lookalike.trackers.health import HealthConfig
from lookalike.viz.overlay import source_frames
from lookalike.viz.video_tracking import (
    fit_video_features,
    side_file,
    track_video,
    write_health_csv,
    write_merges_csv,
)

FEATURE_CHOICES = ("video", "divers")


def run_track_video(video: Path, detections: Path, output: Path, tracker: Any, tracker_name: str, *,
                    annotate: Path | None, team_size: int | None, health_window: int,
                    min_score: float, fps: float | None, features: str = "video") -> None:
    """Track ``detections`` on ``video`` and write ``output``, its ``.health.csv`` (and ``.merges.csv``
    for trackers that merge identities) and, with ``annotate``, the annotated MP4. ``features``: ``video``
    standardises the hand-crafted features on this video's detections, ``divers`` uses the statistics
    calibrated on the rendered validation divers (those diver SORT's thresholds were chosen with)."""
    if features not in FEATURE_CHOICES:
        fail(f"--features: choose one of {', '.join(FEATURE_CHOICES)}, got {features!r}")
    if output.is_dir():
        fail(f"-o/--output: {output} is a folder; with --video give a result file such as tracks.txt")
    try:
        table = read_mot(detections)
        health = HealthConfig(team_size=team_size, window=health_window)
        total = source_frames(video)[1]
        with console.status("standardising appearance features"):
            extractor = (fit_diver_features() if features == "divers"
                         else fit_video_features(video, table, min_score=min_score))
    except (ValueError, FileNotFoundError, OSError) as exc:
        fail(str(exc))
    columns = (TextColumn("tracking {task.description}"), BarColumn(), MofNCompleteColumn(), TimeElapsedColumn())
    try:
        with Progress(*columns, console=console, transient=True) as progress:
            task = progress.add_task(video.name, total=total or None)
            result = track_video(video, table, tracker, extractor, annotate=annotate, health=health,
                                 fps=fps, min_score=min_score, advance=lambda: progress.advance(task))
    except ValueError as exc:
        fail(str(exc))
    except KeyboardInterrupt:
        console.print("\n[yellow]Interrupted.[/]"
                      + (f" {annotate} holds the frames written so far." if annotate else ""))
        raise SystemExit(130) from None
    write_mot(output, result.rows)
    written = [output, write_health_csv(side_file(output, "health"), result.health)]
    if hasattr(tracker, "merges"):
        written.append(write_merges_csv(side_file(output, "merges"), result.merges))
    if annotate is not None:
        written.append(annotate)
    unhealthy = sum(not s.healthy for s in result.health)
    seconds = result.tracker_s + result.feature_s
    fps_text = f"{result.frames / seconds:,.0f}" if seconds > 0 else "inf"
    console.print(
        f"[green]{tracker_name}[/]: {result.frames} frames, {len(result.merges)} merge(s), "
        f"{unhealthy} frame(s) flagged unhealthy, {fps_text} frames/s (features + tracker) → "
        + ", ".join(str(p) for p in written)
    )
    if result.ignored_rows:
        console.print(f"[yellow]note:[/] {result.ignored_rows} detection row(s) are past the video's "
                      f"{result.frames} frames and were ignored")
