"""``lookalike track`` and ``lookalike trackers``."""

from __future__ import annotations

import time
from pathlib import Path
from typing import Any

import typer
from rich.progress import (
    BarColumn,
    MofNCompleteColumn,
    Progress,
    TextColumn,
    TimeRemainingColumn,
)
from rich.table import Table

from lookalike.cli.app import app, console, fail
from lookalike.cli.track_blobs import run_track_blobs
from lookalike.cli.track_pixels import run_track_pixels
from lookalike.cli.track_video import run_track_video
from lookalike.io import (
    find_sequences,
    frames_from_table,
    read_mot,
    tracks_to_rows,
    write_mot,
)
from lookalike.trackers import make_tracker, tracker_names, tracker_parameters
from lookalike.trackers.registry import parse_parameter


def build_tracker(name: str, settings: list[str]) -> Any:
    """A tracker from its name and ``KEY=VALUE`` settings, failing with a readable message."""
    if name not in tracker_names():
        fail(f"unknown tracker {name!r}; choose one of: {', '.join(tracker_names())}")
    try:
        params = dict(parse_parameter(name, s) for s in settings)
        return make_tracker(name, **params)
    except (ValueError, TypeError) as exc:
        fail(str(exc))


@app.command()
def track(
    path: Path | None = typer.Argument(
        None, help="det.txt, a sequence folder, or a folder of sequences (with --video: the det.txt)."
    ),
    output: Path = typer.Option(..., "-o", "--output", help="Result file (single det.txt or --video) or folder."),
    tracker: str = typer.Option("sort", "--tracker", "-t", help="Registered tracker name."),
    set_: list[str] | None = typer.Option(
        None, "--set", "-s", help="Tracker parameter KEY=VALUE (repeatable); see `lookalike trackers`."
    ),
    min_score: float = typer.Option(float("-inf"), help="Drop detections with a lower score."),
    video: Path | None = typer.Option(
        None, "--video", help="Video file or image folder (img1): appearance features from its pixels; also "
        "writes <output stem>.health.csv and, for merging trackers, <output stem>.merges.csv."
    ),
    detections: Path | None = typer.Option(None, "--detections", help="det.txt for --video (or give it as PATH)."),
    annotate: Path | None = typer.Option(
        None, "--annotate", help="With --video: annotated MP4 (uncertain identities dashed with '?', health banner)."
    ),
    team_size: int | None = typer.Option(None, "--team-size", min=0, help="Known number of targets (health checks)."),
    health_window: int = typer.Option(15, "--health-window", min=1, help="Health monitor window in frames."),
    fps: float | None = typer.Option(None, "--fps", min=0.1, help="With --video: frame rate (default: the input's)."),
    features: str = typer.Option("video", "--features", help="With --video: standardise the hand-crafted features "
                                 "on this video's detections ('video') or use the diver calibration ('divers')."),
    detector: str | None = typer.Option(None, "--detector", help="With --video: detect with 'blob' (static camera) "
                                        "instead of reading a det.txt; boxes go to <output stem>.det.txt."),
    blob: list[str] | None = typer.Option(None, "--blob", help="Blob detector setting KEY=VALUE (repeatable), "
                                          "e.g. threshold=30 polarity=dark min_area_px=80 max_area_px=5000."),
    pipeline: str | None = typer.Option(None, "--pipeline", help="With --video: 'robots' finds, orients, places and "
                                        "identifies (-t kalman_ha|kalman_ha2|jpda|lstm) robots from the pixels."),
    reports: Path | None = typer.Option(None, "--reports", help="With --pipeline: heading reports (`simulate` .jsonl)."),
    detector_model: Path | None = typer.Option(None, "--detector-model", help="With --pipeline: `train-detector` model."),
    heading_model: Path | None = typer.Option(None, "--heading-model", help="With --pipeline: `train-heading` model."),
) -> None:
    """Run a tracker over MOTChallenge detections and write MOTChallenge results (on a video with --video)."""
    if pipeline is not None:
        if detector is not None or blob or detections is not None or path is not None:
            fail("--pipeline: finds its own detections; drop --detector/--blob/--detections/PATH")
        run_track_pixels(video, output, pipeline, reports, detector_model, heading_model, tracker, set_ or [],
                         annotate=annotate, fps=fps, min_score=min_score)
        return
    if detector is not None or blob:
        if video is None or detections is not None or path is not None or detector is None:
            fail("--detector/--blob: use --video FILE --detector blob, without det.txt")
        run_track_blobs(video, output, build_tracker(tracker, set_ or []), tracker, detector, blob or [],
                        annotate=annotate, team_size=team_size, health_window=health_window,
                        min_score=min_score, fps=fps, features=features)
        return
    if video is not None:
        det_path = detections or path
        if det_path is None or (detections is not None and path is not None):
            fail("--video: give the detections once, as --detections det.txt (or as PATH)")
        run_track_video(video, det_path, output, build_tracker(tracker, set_ or []), tracker, annotate=annotate,
                        team_size=team_size, health_window=health_window, min_score=min_score, fps=fps,
                        features=features)
        return
    if annotate is not None or detections is not None:
        fail("--annotate/--detections: only with --video")
    if path is None:
        fail("PATH: give det.txt, a sequence folder or a folder of sequences (or --video with --detections)")
    try:
        sequences = [s for s in find_sequences(path) if s.det_path is not None]
    except (FileNotFoundError, ValueError) as exc:
        fail(str(exc))
    if not sequences:
        fail(f"{path}: no det/det.txt found")
    single_file = path.is_file()
    trk = build_tracker(tracker, set_ or [])
    loaded = []
    for seq in sequences:
        try:
            table = read_mot(seq.det_path)
        except ValueError as exc:
            fail(str(exc))
        loaded.append((seq, table))
    total_frames, total_time = 0, 0.0
    columns = (TextColumn("{task.description}"), BarColumn(), MofNCompleteColumn(), TimeRemainingColumn())
    with Progress(*columns, console=console, transient=True) as progress:
        overall = progress.add_task("sequences", total=len(loaded))
        for seq, table in loaded:
            trk.reset()
            frames = list(frames_from_table(table, seq.length, seq.frame_rate, min_score))
            task = progress.add_task(seq.name, total=len(frames))
            rows = []
            for frame in frames:
                t0 = time.perf_counter()
                tracks = trk.update(frame)
                total_time += time.perf_counter() - t0
                rows.append(tracks_to_rows(frame.index, tracks))
                progress.advance(task)
            target = output if single_file else output / f"{seq.name}.txt"
            write_mot(target, rows)
            total_frames += len(frames)
            progress.remove_task(task)
            progress.advance(overall)
    fps = total_frames / total_time if total_time > 0 else float("inf")
    where = output if single_file else f"{output}/<sequence>.txt"
    console.print(
        f"[green]{tracker}[/]: {len(loaded)} sequence(s), {total_frames} frames, "
        f"{fps:,.0f} frames/s (tracker only) → {where}"
    )


@app.command()
def trackers(
    names: bool = typer.Option(False, "--names", help="Print only the names, one per line."),
) -> None:
    """List registered trackers and their parameters with defaults."""
    if names:
        for name in tracker_names():
            typer.echo(name)
        return
    for name in tracker_names():
        table = Table(title=f"[bold]{name}[/]", title_justify="left", show_lines=False)
        table.add_column("parameter")
        table.add_column("type")
        table.add_column("default")
        table.add_column("meaning")
        for p in tracker_parameters(name):
            table.add_row(p.name, p.type, repr(p.default), p.doc)
        console.print(table)
    console.print("Set any parameter with [bold]--set KEY=VALUE[/] on `lookalike track`.")
