"""``lookalike render-robots``: a simulated robot sequence drawn through the robot camera, the input of ``lookalike
track --video FILE --pipeline robots`` (run by :func:`lookalike.pipeline.robots.run_robots`)."""

from __future__ import annotations

from pathlib import Path

import typer

from lookalike.cli.app import app, check_outputs_or_fail, console, failing, require
from lookalike.cli.progress import bars
from lookalike.pipeline.robots import robot_video


@app.command("render-robots")
def render_robots(
    sequence: Path = typer.Argument(..., help="A robot sequence written by `lookalike simulate` (.jsonl)."),
    output: Path = typer.Option(..., "-o", "--output", help="MP4 to write."),
    seed: int = typer.Option(0, min=0, help="Seed of the lighting, blur and pixel noise."),
) -> None:
    """Draw a simulated robot sequence through the robot camera (640×480, 70°) as a video: the input of
    `lookalike track --video FILE --pipeline robots --reports SEQUENCE`."""
    from lookalike.viz.video import VideoWriter

    require("cv2")
    check_outputs_or_fail({"-o/--output": output}, [sequence])
    with failing(ValueError, OSError):
        seq, frames = robot_video(sequence, seed)
    with bars("rendering") as progress, VideoWriter(output, fps=seq.config.frame_rate_hz) as writer:
        task = progress.add_task("render", total=len(seq))
        for image in frames:
            writer.write(image)
            progress.advance(task)
    console.print(f"wrote {output} ({len(seq)} frames)", markup=False)
