"""``lookalike render``: overlay MOTChallenge tracking results on a video (MP4, optional GIF)."""

from __future__ import annotations

from pathlib import Path

import typer
from rich.progress import (
    BarColumn,
    MofNCompleteColumn,
    Progress,
    TextColumn,
    TimeElapsedColumn,
)

from lookalike.cli.app import app, console, fail
from lookalike.io import read_mot
from lookalike.viz.overlay import overlay_tracks, source_frames


@app.command()
def render(
    video: Path = typer.Option(..., "--video", help="Video file, or a folder of images (e.g. a MOTChallenge img1)."),
    tracks: Path = typer.Option(..., "--tracks", help="MOTChallenge result file (frame,id,x,y,w,h,...)."),
    output: Path = typer.Option(..., "-o", "--output", help="Annotated MP4 to write."),
    gif: Path | None = typer.Option(None, "--gif", help="Also write a short animated GIF here."),
    tail: int = typer.Option(25, min=1, help="Track tail length in frames."),
    fps: float | None = typer.Option(None, min=0.1, help="Output frame rate (default: the input's; 30 for images)."),
) -> None:
    """Draw tracks (identity colours, ids, tails) on every frame of a video."""
    try:
        table = read_mot(tracks)
        _, total, _ = source_frames(video)
    except (ValueError, FileNotFoundError, OSError) as exc:
        fail(str(exc))
    try:
        with Progress(TextColumn("rendering"), BarColumn(), MofNCompleteColumn(), TimeElapsedColumn(),
                      console=console) as progress:
            task = progress.add_task("render", total=total or None)
            n = overlay_tracks(video, table, output, gif=gif, tail=tail, fps=fps,
                               advance=lambda: progress.advance(task))
    except ValueError as exc:
        fail(str(exc))
    except KeyboardInterrupt:
        console.print(f"\n[yellow]Interrupted.[/] {output} holds the frames written so far.")
        raise typer.Exit(130) from None
    console.print(f"wrote {output} ({n} frames)" + (f" and {gif}" if gif else ""))
