"""``lookalike bench divers``: the paper's Table 2 and Figure 5 (:mod:`lookalike.bench.divers`)."""

from __future__ import annotations

import json
from pathlib import Path

import typer
from rich.console import Console
from rich.table import Column, Table

from lookalike.bench.divers import COLUMNS, bar_chart, diver_table
from lookalike.bench.tables import write_rows
from lookalike.cli.app import console, fail
from lookalike.cli.bench import bench_app

GROUPED = ("Scenario", "Location", "DP", "DR")  # printed once per scenario


@bench_app.command("divers")
def divers(
    scenario_names: list[str] | None = typer.Option(None, "--scenario", help="Scenario name (repeatable)."),
    frames: int | None = typer.Option(None, min=10, help="Shorten every scenario to this many frames."),
    png: Path | None = typer.Option(None, "--png", help="Write the IDF1 bar chart here."),
    json_path: Path | None = typer.Option(None, "--json", help="Write the table as JSON rows."),
    csv_path: Path | None = typer.Option(None, "--csv", help="Write the table as CSV."),
) -> None:
    """SORT vs deep SORT style vs diver SORT on the rendered diver scenarios (paper Table 2)."""
    try:
        rows = diver_table(scenario_names, frames=frames)
    except ValueError as exc:
        fail(str(exc))
    table = Table(*(Column(c, no_wrap=True) for c in COLUMNS))
    for k, r in enumerate(rows):
        first = k == 0 or r["Scenario"] != rows[k - 1]["Scenario"]
        table.add_row(*(str(r[c]) if first or c not in GROUPED else "" for c in COLUMNS))
    Console(width=max(console.width, 120)).print(table)  # the table is wider than a default terminal
    if json_path:
        json_path.parent.mkdir(parents=True, exist_ok=True)
        json_path.write_text(json.dumps(rows, indent=1))
    write_rows(rows, None, csv_path, COLUMNS)
    if png:
        console.print(f"bar chart → {bar_chart(rows, png)}")
