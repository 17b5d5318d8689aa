"""``lookalike demo``: the whole system on built-in simulated data, with videos, plots and a report.

A robot scene (identical robots identified from their heading reports) and a diver scene (look-alike
divers re-identified after long absences) are simulated, rendered and tracked by every relevant
tracker; the robot identification table covers the three paper set-ups and the diver table every
test scenario (shortened). Everything lands in ``demo-out/`` with a self-contained ``report.html``.
``--quick`` runs a reduced version (seconds) used by the test suite.
"""

from __future__ import annotations

import dataclasses
import json
import time
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

import typer
from rich.progress import (
    BarColumn,
    MofNCompleteColumn,
    Progress,
    TextColumn,
    TimeElapsedColumn,
)
from rich.table import Table

from lookalike.cli.app import app, console
from lookalike.cli.bench import ident_table
from lookalike.sim import PRESET_NAMES, preset, preset_label
from lookalike.sim.divers import SCENARIOS, VALIDATION_SCENARIOS, scenario
from lookalike.sim.divers_run import fit_diver_features
from lookalike.viz.divers_scene import run_diver_scenario
from lookalike.viz.plots import grouped_bar_chart
from lookalike.viz.report import HtmlReport
from lookalike.viz.robots_scene import run_robot_scene

ROBOT_TRACKERS = ("kalman_ha", "kalman_ha2", "jpda")
DIVER_TRACKERS = ["sort", "deepsort", "diversort"]


@dataclasses.dataclass(frozen=True)
class DemoSize:
    """How much the demo simulates (frames per scene and table)."""

    robot_frames: int = 300
    ident_sequences: int = 2
    ident_frames: int = 600
    diver_video_frames: int = 300
    diver_frames: int = 150
    diver_scenarios: int = len(SCENARIOS)
    fit_frames: int = 150


QUICK = DemoSize(robot_frames=45, ident_sequences=1, ident_frames=120, diver_video_frames=40, diver_frames=30,
                 diver_scenarios=2, fit_frames=30)


def lstm_status(setup: str) -> str | None:
    """None when shipped LSTM weights exist for preset ``setup``, else why the LSTM is left out."""
    from lookalike.learn.checkpoint import CheckpointError
    from lookalike.learn.weights import shipped_weights_path

    cfg = preset(setup)
    try:
        shipped_weights_path(cfg.n_agents, cfg.max_detections)
    except CheckpointError:
        return f"no shipped LSTM weights for {preset_label(setup)} (train them with `make train`)"
    return None


def _progress() -> Progress:
    return Progress(TextColumn("{task.description:<42}"), BarColumn(), MofNCompleteColumn(), TimeElapsedColumn(),
                    console=console, transient=False)


@contextmanager
def _task(progress: Progress, description: str, total: int) -> Iterator[Any]:
    task = progress.add_task(description, total=total)
    yield lambda: progress.advance(task)
    progress.update(task, completed=total)


def _rich_table(title: str, rows: list[dict[str, Any]], columns: list[str]) -> Table:
    table = Table(title=title)
    for c in columns:
        table.add_column(c, justify="left" if c in ("Setup", "Tracker", "Scenario") else "right")
    for r in rows:
        table.add_row(*(f"{r[c]:,}" if isinstance(r[c], (int, float)) else str(r[c]) for c in columns))
    return table


def run_demo(output: Path, seed: int, size: DemoSize, robot_preset: str, rerun: Any = None) -> dict[str, Path]:
    """Run the whole demo into ``output``; returns the files written (name → path). ``rerun``: an
    optional :class:`~lookalike.viz.rerun_log.RerunLogger` that also receives the video scenes."""
    output.mkdir(parents=True, exist_ok=True)
    notes = {s: lstm_status(s) for s in PRESET_NAMES}
    for s, why in notes.items():
        if why:
            console.print(f"[yellow]LSTM left out for {preset_label(s)}:[/] {why}")
    video_tracker = "lstm" if notes[robot_preset] is None else "kalman_ha2"
    files: dict[str, Path] = {}
    with _progress() as progress:
        robot_trackers = list(ROBOT_TRACKERS) + (["lstm"] if notes[robot_preset] is None else [])
        with _task(progress, f"Robots {preset_label(robot_preset)}: render + identify", size.robot_frames) as adv:
            robots = run_robot_scene(output, preset_name=robot_preset, frames=size.robot_frames, seed=seed,
                                     trackers=robot_trackers, video_tracker=video_tracker, advance=adv,
                                     rerun=rerun)
        files.update({f"robots-{k}": v for k, v in robots.files.items()})
        ident_rows: list[dict[str, Any]] = []
        with _task(progress, "Robot identification, all set-ups", len(PRESET_NAMES)) as adv:
            for s in PRESET_NAMES:
                names = list(ROBOT_TRACKERS) + (["lstm"] if notes[s] is None else [])
                ident_rows += ident_table([s], names, size.ident_sequences, size.ident_frames, seed=900_000 + seed)
                adv()
        with _task(progress, "Divers: appearance features (validation)", 1) as adv:
            val = tuple(dataclasses.replace(sc, frames=min(sc.frames, size.fit_frames)) for sc in VALIDATION_SCENARIOS)
            extractor = fit_diver_features(val)
            adv()
        video_sc = dataclasses.replace(scenario("ocean_four_long_absences"), frames=size.diver_video_frames)
        with _task(progress, f"Divers {video_sc.name}: render + track", video_sc.frames) as adv:
            diver_rows, diver_files = run_diver_scenario(video_sc, extractor, DIVER_TRACKERS, out_dir=output,
                                                         video_tracker="diversort", advance=adv,
                                                         rerun=rerun)
        files.update({f"divers-{k}": v for k, v in diver_files.items()})
        others = [sc for sc in SCENARIOS if sc.name != video_sc.name][: max(size.diver_scenarios - 1, 0)]
        with _task(progress, "Divers: other scenarios", len(others) * size.diver_frames) as adv:
            for sc in others:
                rows, _ = run_diver_scenario(dataclasses.replace(sc, frames=size.diver_frames), extractor,
                                             DIVER_TRACKERS, advance=adv)
                diver_rows += rows
    ident_cols = ["Setup", "Tracker", "Success rate (%)", "Localisation error (m)", "Frames/s"]
    console.print(_rich_table(f"Robot video scene ({preset_label(robot_preset)}, {size.robot_frames} frames)",
                              robots.rows, ident_cols))
    console.print(_rich_table(f"Robot identification ({size.ident_sequences} × {size.ident_frames} frames per set-up)",
                              ident_rows, ident_cols))
    diver_cols = ["Scenario", "Tracker", "IDF1", "HOTA", "MOTA", "IDSW", "Frames/s"]
    console.print(_rich_table("Diver tracking (IDF1, HOTA, MOTA in %)", diver_rows, diver_cols))
    files["idf1"] = grouped_bar_chart(output / "divers-idf1.png", diver_rows, "Scenario", "Tracker", "IDF1",
                                      ylabel="IDF1 (%)", title="Diver tracking: IDF1 per scenario")
    files["ident-chart"] = grouped_bar_chart(output / "robots-ident.png", ident_rows, "Setup", "Tracker",
                                             "Success rate (%)", title="Robot identification success rate")
    (output / "robots-ident.json").write_text(json.dumps(ident_rows, indent=1) + "\n")
    (output / "divers.json").write_text(json.dumps(diver_rows, indent=1) + "\n")
    files["report"] = _report(output, files, robots.rows, ident_rows, diver_rows, ident_cols, diver_cols,
                              video_tracker, notes, size)
    return files


def _report(output: Path, files: dict[str, Path], video_rows: list[dict[str, Any]], ident_rows: list[dict[str, Any]],
            diver_rows: list[dict[str, Any]], ident_cols: list[str], diver_cols: list[str], video_tracker: str,
            notes: dict[str, str | None], size: DemoSize) -> Path:
    report = HtmlReport("lookalike demo: identical robots and look-alike divers")
    report.text("Everything here was simulated and rendered by lookalike itself; no data was downloaded. "
                "Re-run with `lookalike demo`.", note=True)
    report.heading("Identical robots identified from their heading reports")
    report.text(f"Each detection is labelled with the robot it belongs to (colours) or as a false positive, by "
                f"the {video_tracker} identifier, from the robots' own heading reports. Red frames mark wrong labels.")
    report.image(files["robots-still"], "A frame of the annotated robot video", width=480)
    report.image(files["robots-gif"], "The first seconds (GIF)", width=320)
    report.link(files["robots-video"], "Full annotated robot video (MP4)", relative_to=output)
    report.image(files["robots-birdseye"], "True vs estimated robot paths, seen from above", width=560)
    report.table(video_rows, ident_cols, caption="The video scene")
    report.heading("Robot identification, the paper's three set-ups")
    for why in (w for w in notes.values() if w):
        report.text(f"LSTM left out: {why}.", note=True)
    report.table(ident_rows, ident_cols,
                 caption=f"{size.ident_sequences} × {size.ident_frames} simulated frames per set-up")
    report.image(files["ident-chart"], "Identification success rate (%)", width=560)
    report.heading("Look-alike divers re-identified after long absences")
    report.image(files["divers-still"], "A frame of the annotated diver video (diver SORT)", width=480)
    report.image(files["divers-gif"], "The first seconds (GIF)", width=320)
    report.link(files["divers-video"], "Full annotated diver video (MP4)", relative_to=output)
    report.image(files["idf1"], "IDF1 per scenario and tracker", width=640)
    report.table(diver_rows, diver_cols, caption="Diver tracking (IDF1, HOTA, MOTA in %; scenarios shortened)")
    report.heading("Try next")
    report.code("lookalike trackers\n"
                "lookalike bench ident\n"
                "lookalike bench divers --png idf1.png\n"
                f"lookalike render --video {output}/divers-raw.mp4 --tracks {output}/divers-sort.txt "
                f"-o {output}/divers-sort.mp4")
    return report.write(output / "report.html")


@app.command()
def demo(
    output: Path = typer.Option(Path("demo-out"), "-o", "--output", help="Folder for the results."),
    seed: int = typer.Option(0, help="Seed of the simulated scenes."),
    quick: bool = typer.Option(False, "--quick", help="A reduced run (seconds): fewer frames and scenarios."),
    robot_preset: str = typer.Option("m5n3", "--robot-preset", help=f"Robot set-up of the video: {', '.join(PRESET_NAMES)}."),
    rerun: bool = typer.Option(False, "--rerun", help="Also stream frames, boxes and positions to a Rerun viewer "
                                                      "(needs the optional rerun-sdk)."),
    rerun_save: Path | None = typer.Option(None, "--rerun-save", help="Also write a Rerun recording (.rrd) here."),
) -> None:
    """Simulate robots and divers, run every relevant tracker, write videos, plots and an HTML report."""
    from lookalike.cli.app import fail

    if robot_preset not in PRESET_NAMES:
        fail(f"--robot-preset: unknown preset {robot_preset!r}; known: {', '.join(PRESET_NAMES)}")
    logger = None
    if rerun or rerun_save is not None:
        from lookalike.viz.rerun_log import open_rerun

        try:
            logger = open_rerun("lookalike-demo", save=rerun_save, spawn=rerun)
        except ValueError as exc:
            fail(str(exc))
    t0 = time.perf_counter()
    try:
        files = run_demo(output, seed, QUICK if quick else DemoSize(), robot_preset, rerun=logger)
    except KeyboardInterrupt:
        console.print(f"\n[yellow]Interrupted.[/] Files finished so far are in {output}/.")
        raise typer.Exit(130) from None
    finally:
        if logger is not None:
            logger.close()
    console.print(f"\nDone in {time.perf_counter() - t0:.0f} s. Results are in [bold]{output}/[/]:")
    console.print(f"  report      {files['report']}   (open it in a browser: tables, pictures, links to videos)")
    console.print(f"  videos      {files['robots-video']}, {files['divers-video']} (and .gif)")
    console.print(f"  plots       {files['robots-birdseye']}, {files['idf1']}")
    console.print("Try next: `lookalike trackers` (every tracker and its paper), `lookalike bench ident`, "
                  "`lookalike bench divers`,")
    console.print(f"  `lookalike render --video {output}/divers-raw.mp4 --tracks {output}/divers-sort.txt "
                  f"-o {output}/divers-sort.mp4`")
    if rerun_save is not None:
        console.print(f"  `rerun {rerun_save}` to inspect the logged frames, boxes and positions")
