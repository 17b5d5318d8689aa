"""``lookalike demo``: the most complete pipeline the project has, on built-in simulated data."""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np
import typer
from rich.table import Table

from lookalike.cli.app import app, console
from lookalike.eval import evaluate_sequence
from lookalike.io import MotTable, tracks_to_rows, write_mot
from lookalike.sim import BoxSceneConfig, simulate_boxes
from lookalike.trackers import make_tracker


@app.command()
def demo(
    output: Path = typer.Option(Path("demo-out"), "-o", "--output", help="Folder for the results."),
    seed: int = typer.Option(0, help="Seed of the simulated scenes."),
) -> None:
    """Simulate a scene, run the trackers on it, and print how they did."""
    scene = simulate_boxes(BoxSceneConfig(seed=seed))
    output.mkdir(parents=True, exist_ok=True)
    write_mot(output / "boxes-gt.txt", scene.gt)
    table = Table(title="Simulated box scene: 6 targets, 300 frames")
    table.add_column("tracker")
    for column in ("MOTA", "IDF1", "HOTA", "IDSW", "frames/s"):
        table.add_column(column, justify="right")
    for name in ["sort"]:
        tracker = make_tracker(name)
        rows, t0 = [], time.perf_counter()
        for frame in scene.frames:
            rows.append(tracks_to_rows(frame.index, tracker.update(frame)))
        elapsed = time.perf_counter() - t0
        path = write_mot(output / f"boxes-{name}.txt", rows)
        s = evaluate_sequence(MotTable.from_rows(scene.gt), MotTable.from_rows(np.vstack(rows)), num_frames=len(scene.frames))
        table.add_row(
            name, f"{100 * s['MOTA']:.1f}", f"{100 * s['IDF1']:.1f}", f"{100 * s['HOTA']:.1f}",
            str(int(s["IDSW"])), f"{len(scene.frames) / elapsed:,.0f}",
        )
        console.print(f"wrote {path}")
    console.print(table)
    console.print(f"Results are in [bold]{output}/[/]. Try `lookalike trackers` to see every tracker.")

