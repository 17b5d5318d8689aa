"""``lookalike render``: overlay MOTChallenge tracking results on a video, or draw world tracks from above."""

from __future__ import annotations

from contextlib import ExitStack
from pathlib import Path

import typer
from rich.markup import escape

from lookalike.cli.app import app, check_outputs_or_fail, console, fail, failing, warn
from lookalike.cli.progress import bars
from lookalike.io import read_mot
from lookalike.io.outputs import atomic_path
from lookalike.io.video_frames import source_frames
from lookalike.viz.overlay import birdseye_video, overlay_tracks, undrawn


@app.command()
def render(
    tracks: Path = typer.Option(..., "--tracks", help="MOTChallenge result file (frame,id,x,y,w,h,conf,wx,wy,wz)."),
    output: Path = typer.Option(..., "-o", "--output", help="Annotated MP4 to write."),
    video: Path | None = typer.Option(None, "--video", help="Video file, or a folder of images (e.g. a MOTChallenge "
                                                            "img1); needed unless --birdseye."),
    birdseye: bool = typer.Option(False, "--birdseye", help="Draw the world positions (columns 8, 9, metres; the box "
                                                            "may be 0,0,0,0) from above instead of boxes on a video."),
    gif: Path | None = typer.Option(None, "--gif", help="Also write a short animated GIF here."),
    tail: int = typer.Option(25, min=1, help="Track tail length in frames."),
    fps: float | None = typer.Option(None, min=0.1, help="Output frame rate (default: the input's; 30 otherwise)."),
) -> None:
    """Draw tracks (identity colours, ids, tails) on every frame of a video, or from above (--birdseye)."""
    check_outputs_or_fail({"-o/--output": output, "--gif": gif}, [tracks, video], input_folders=[video])
    if video is None and not birdseye:
        fail("--video: give the video to draw on (or --birdseye for world tracks seen from above)")
    with failing(ValueError, OSError):
        table = read_mot(tracks, min_columns=6)
        total = int(table.frame.max()) if birdseye and len(table) else source_frames(video)[1] if video else 0
    interrupted = False
    # (the files are written to temporary files beside them, renamed into place when closed)
    with atomic_path(output) as out, ExitStack() as stack:
        gif_out = stack.enter_context(atomic_path(gif)) if gif is not None else None
        try:
            with bars("rendering", transient=False) as progress:
                task = progress.add_task("render", total=total or None)

                def advance() -> None:
                    progress.advance(task)

                if birdseye:
                    n = birdseye_video(table, out, fps=fps or 30.0, gif=gif_out, tail=tail, advance=advance)
                else:
                    assert video is not None
                    n = overlay_tracks(video, table, out, gif=gif_out, tail=tail, fps=fps, advance=advance)
        except ValueError as exc:
            fail(str(exc))
        except KeyboardInterrupt:
            interrupted = True
    if interrupted:
        console.print(f"\n[yellow]Interrupted.[/] {escape(str(output))} holds the frames written so far.")
        raise typer.Exit(130)
    console.print(f"wrote {output} ({n} frames)" + (f" and {gif}" if gif else ""), markup=False)
    problem = None if birdseye else undrawn(table, n)
    if problem is not None:
        warn(f"{tracks}: {problem}")
