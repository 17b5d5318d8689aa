"""``lookalike demo``: the whole system on built-in simulated data (:mod:`lookalike.demo`),
with videos, plots and a report in ``demo-out/``. ``--quick`` runs a reduced version (seconds)."""

from __future__ import annotations

import time
from collections.abc import Callable
from pathlib import Path

import typer
from rich.markup import escape
from rich.progress import TimeRemainingColumn

from lookalike._optional import MissingExtra
from lookalike.cli.app import app, check_names, check_outputs_or_fail, command_line, console, failing, require
from lookalike.cli.bench import rich_table
from lookalike.cli.progress import bars
from lookalike.demo import DIVER_COLS, IDENT_COLS, QUICK, DemoSize, lstm_status, run_demo
from lookalike.sim import PRESET_NAMES, preset_label

__all__ = ["QUICK", "demo", "lstm_status", "run_demo"]


def _open_rerun(rerun: bool, rerun_save: Path | None) -> object | None:
    if not rerun and rerun_save is None:
        return None
    from lookalike.viz.rerun_log import open_rerun

    with failing(ValueError, OSError, MissingExtra, prefix="--rerun: " if rerun else "--rerun-save: "):
        return open_rerun("lookalike-demo", save=rerun_save, spawn=rerun)


def _run(output: Path, seed: int, size: DemoSize, robot_preset: str, logger: object | None) -> dict[str, Path]:
    for s in PRESET_NAMES:
        why = lstm_status(s)
        if why:
            console.print(f"[yellow]LSTM left out for {preset_label(s)}:[/] {escape(str(why))}")
    with bars("{task.description:<42}", TimeRemainingColumn(), transient=False) as progress:
        def step(description: str, total: int) -> Callable[[], None]:
            task = progress.add_task(description, total=total)
            return lambda: progress.advance(task)

        result = run_demo(output, seed, size, robot_preset, rerun=logger, step=step, command=command_line())
    console.print(rich_table(f"Robot video scene ({preset_label(robot_preset)}, {size.robot_frames} frames)",
                             result.robot_rows, IDENT_COLS))
    console.print(rich_table(f"Robot identification ({size.ident_sequences} × {size.ident_frames} frames per set-up)",
                             result.ident_rows, IDENT_COLS))
    console.print(rich_table("Diver tracking (IDF1, HOTA, MOTA in %)", result.diver_rows, DIVER_COLS))
    return result.files


@app.command()
def demo(
    output: Path = typer.Option(Path("demo-out"), "-o", "--output", help="Folder for the results."),
    seed: int = typer.Option(0, min=0, help="Seed of the simulated scenes."),
    quick: bool = typer.Option(False, "--quick", help="A reduced run (seconds): fewer frames and scenarios."),
    robot_preset: str = typer.Option("m5n3", "--robot-preset",
                                     help=f"Robot set-up of the video: {', '.join(PRESET_NAMES)}."),
    rerun: bool = typer.Option(False, "--rerun", help="Also stream frames, boxes and positions to a Rerun viewer "
                                                      "(needs the optional rerun-sdk)."),
    rerun_save: Path | None = typer.Option(None, "--rerun-save", help="Also write a Rerun recording (.rrd) here."),
) -> None:
    """Simulate robots and divers, run every relevant tracker, write videos, plots and an HTML report."""
    require("cv2", "matplotlib")
    if rerun or rerun_save is not None:
        with failing(MissingExtra, prefix="--rerun: " if rerun else "--rerun-save: "):
            require("rerun")
    check_outputs_or_fail({"-o/--output": output, "--rerun-save": rerun_save}, folders={"-o/--output"})
    check_names("--robot-preset", [robot_preset], PRESET_NAMES, "preset")
    logger = _open_rerun(rerun, rerun_save)
    t0 = time.perf_counter()
    try:
        files = _run(output, seed, QUICK if quick else DemoSize(), robot_preset, logger)
    except KeyboardInterrupt:
        console.print(f"\n[yellow]Interrupted.[/] Files finished so far are in {escape(str(output))}/.")
        raise typer.Exit(130) from None
    finally:
        if logger is not None:
            logger.close()  # type: ignore[attr-defined]
    console.print(f"\nDone in {time.perf_counter() - t0:.0f} s. Results are in [bold]{escape(str(output))}/[/]:")
    console.print(f"  report      {files['report']}   (open it in a browser: tables, pictures, videos)")
    console.print(f"  videos      {files['robots-video']}, {files['divers-video']} (and .gif)")
    console.print(f"  plots       {files['robots-birdseye']}, {files['idf1']}")
    console.print("Try next: `lookalike trackers` (every tracker and its paper), `lookalike bench ident`, "
                  "`lookalike bench divers`,")
    console.print(f"  `lookalike render --video {output}/divers-raw.mp4 --tracks {output}/divers-sort.txt "
                  f"-o {output}/divers-sort.mp4`")
    if rerun_save is not None:
        console.print(f"  `rerun {rerun_save}` to inspect the logged frames, boxes and positions")
