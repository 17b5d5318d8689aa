"""``lookalike track --video FILE --pipeline robots`` and ``--bag DIR`` (robot identities from pixels, run by
:mod:`lookalike.pipeline.robots`): options checked and the run printed; and ``lookalike render-robots``."""

from __future__ import annotations

from pathlib import Path

import typer
from rich.markup import escape

from lookalike.cli.app import app, check_outputs_or_fail, console, failing
from lookalike.cli.progress import bars
from lookalike.pipeline.robots import check_robots, dropped, identify_robots, prepare_robots, robot_video


def run_track_pixels(video: Path | None, output: Path, pipeline: str, reports: Path | None, detector_model: Path | None,
                     heading_model: Path | None, identifier: str, settings: list[str], *,
                     annotate: Path | None = None, fps: float | None = None, min_score: float = 0.5,
                     annotate_as: Path | None = None, bag: Path | None = None, camera_topic: str | None = None,
                     heading_topics: str | None = None) -> None:
    """Run pipeline ``pipeline`` over ``video`` with the reports of ``reports`` (or over the rosbag2 folder ``bag``:
    images of ``camera_topic``, headings of the comma-separated ``heading_topics``); write MOTChallenge rows to
    ``output`` and, with ``annotate``, an annotated MP4 (printed as ``annotate_as``). ``min_score``: detector
    probability (-inf: 0.5)."""
    with failing(ValueError):
        identifier = check_robots(video, pipeline, reports, identifier, output, bag, camera_topic)
    with failing(ValueError, OSError, TypeError, prefix="" if bag is None else "--bag: "):
        run = prepare_robots(video, reports, identifier, settings, detector_model, heading_model, min_score, bag=bag,
                             camera_topic=camera_topic, heading_topics=heading_topics)
    with failing(ValueError), bars("identifying robots") as progress:
        task = progress.add_task(run.source.name, total=run.total or None)
        stats = identify_robots(run, output, annotate, fps, advance=lambda: progress.advance(task))
    speed = f"{stats.fps:,.1f}" if stats.seconds > 0 else "inf"
    where = escape(f"{output}" + (f", {annotate_as or annotate}" if annotate else ""))
    console.print(f"[green]{identifier}[/] from pixels: {stats.frames} frames, {speed} frames/s (detector + heading + "
                  f"identifier) → {where}")
    if dropped(run.pipe):
        console.print(f"dropped as implausible: {dropped(run.pipe)}", markup=False)


@app.command("render-robots")
def render_robots(
    sequence: Path = typer.Argument(..., help="A robot sequence written by `lookalike simulate` (.jsonl)."),
    output: Path = typer.Option(..., "-o", "--output", help="MP4 to write."),
    seed: int = typer.Option(0, help="Seed of the lighting, blur and pixel noise."),
) -> None:
    """Draw a simulated robot sequence through the robot camera (640×480, 70°) as a video: the input of
    `lookalike track --video FILE --pipeline robots --reports SEQUENCE`."""
    from lookalike.viz.video import VideoWriter

    check_outputs_or_fail({"-o/--output": output}, [sequence])
    with failing(ValueError, OSError):
        seq, frames = robot_video(sequence, seed)
    with bars("rendering") as progress, VideoWriter(output, fps=seq.config.frame_rate_hz) as writer:
        task = progress.add_task("render", total=len(seq))
        for image in frames:
            writer.write(image)
            progress.advance(task)
    console.print(f"wrote {output} ({len(seq)} frames)", markup=False)
