"""``lookalike bench divers``: the paper's Table 2 and Figure 5 (:mod:`lookalike.bench.divers`)."""

from __future__ import annotations

import math
from pathlib import Path

import typer
from rich.console import Console
from rich.table import Column, Table

from lookalike.bench.divers import COLUMNS, TRACKERS, bar_chart, diver_results, diver_table, pearson
from lookalike.cli.app import check_outputs_or_fail, command_line, console, fail, failing, split_list
from lookalike.cli.bench import bench_app, write_csv, write_results
from lookalike.sim.divers_paper import DETECTION_LEVELS

GROUPED = ("Scenario", "Location", "DP", "DR")  # printed once per scenario
ENTRY_HELP = f"Entries (comma-separated or repeated): {', '.join(TRACKERS)}."


@bench_app.command("divers")
def divers(
    scenario_names: list[str] | None = typer.Option(None, "--scenario", "--scenarios",
                                                    help="Scenario names (comma-separated or repeated)."),
    frames: int | None = typer.Option(None, min=10, help="Frames per scenario (default: each scenario's 300; fewer "
                                      "cuts it short, more draws it longer)."),
    trackers: list[str] | None = typer.Option(None, "--trackers", "--tracker", help=ENTRY_HELP),
    features: list[str] | None = typer.Option(None, "--features", help="Feature set (repeatable): handcrafted, "
                                              "learned or FILE.onnx; deep SORT and diver SORT run with each "
                                              "(default: handcrafted and learned, the entries above)."),
    detections: str = typer.Option("sim", "--detections", help="Detector level: 'sim' (the scenarios' own), "
                                   "'paper' (the diver-tracking paper's DP/DR per video) or 'both' (one table each)."),
    seed: int = typer.Option(0, min=0, help="Scenario draw: 0 the published scenarios, others new draws."),
    png: Path | None = typer.Option(None, "--png", help="Write the IDF1 bar chart here (of the last table)."),
    json_path: Path | None = typer.Option(None, "--json", help="Write the results document (JSON)."),
    csv_path: Path | None = typer.Option(None, "--csv", help="Write the table(s) as CSV (a Detections column first)."),
) -> None:
    """SORT, deep SORT and diver SORT with hand-crafted or learned features on the rendered divers (Table 2)."""
    check_outputs_or_fail({"--png": png, "--json": json_path, "--csv": csv_path})
    levels = list(DETECTION_LEVELS) if detections == "both" else [detections]
    if detections != "both" and detections not in DETECTION_LEVELS:
        fail(f"--detections: choose one of {', '.join(DETECTION_LEVELS)} or both, got {detections!r}")
    scenario_list, entries = split_list(scenario_names), split_list(trackers)
    for option, given, names in (("--scenario", scenario_names, scenario_list), ("--trackers", trackers, entries)):
        if given and not names:
            fail(f"{option}: no name given (leave the option out for every one)")
    with failing(ValueError, FileNotFoundError):
        tables = {level: diver_table(scenario_list or None, tuple(entries) or None, frames=frames,
                                     detections=level, seed=seed,
                                     features=tuple(features) if features else ("handcrafted", "learned"))
                  for level in levels}
    wide = Console(width=max(console.width, 120))  # the table is wider than a default terminal
    for level, rows in tables.items():
        table = Table(*(Column(c, no_wrap=True) for c in COLUMNS), title=f"detections: {level}, seed {seed}")
        for k, r in enumerate(rows):
            first = k == 0 or r["Scenario"] != rows[k - 1]["Scenario"]
            table.add_row(*(str(r[c]) if first or c not in GROUPED else "" for c in COLUMNS))
        wide.print(table)
        console.print("Pearson r between DP and IDP over the scenarios (p): " + ", ".join(
            f"{t} {r:.3f} ({p:.3f})" if not math.isnan(r) else f"{t} n/a" for t, (r, p) in pearson(rows).items()))
    frames_run = frames or 300
    write_results(diver_results(tables, frames_run, seed, command_line()), json_path)
    all_rows = [{"Detections": level, **r} for level, rows in tables.items() for r in rows]
    write_csv(all_rows, csv_path, ("Detections", *COLUMNS))
    if png:
        try:
            chart = bar_chart(tables[levels[-1]], png)
        except OSError as exc:
            fail(f"--png: cannot write {png}: {exc.strerror or exc}")
        console.print(f"bar chart → {chart}", markup=False)
