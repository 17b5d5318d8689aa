"""``lookalike trackers``: the registered trackers and their parameters."""

from __future__ import annotations

import typer

from lookalike.cli.app import app, console
from lookalike.trackers.registry import tracker_names, tracker_parameters


@app.command()
def trackers(
    names: bool = typer.Option(False, "--names", help="Print only the names, one per line."),
) -> None:
    """List registered trackers and their parameters with defaults and allowed values."""
    if names:  # the names alone: no tracker module is imported
        typer.echo("\n".join(tracker_names()))
        return
    from rich.table import Table

    for name in tracker_names():
        table = Table(title=f"[bold]{name}[/]", title_justify="left", show_lines=False)
        table.add_column("parameter")
        table.add_column("type")
        table.add_column("default")
        table.add_column("allowed")
        table.add_column("meaning")
        for p in tracker_parameters(name):
            table.add_row(p.name, p.type, repr(p.default), p.allowed(), p.doc)
        console.print(table)
    console.print("Set any parameter with [bold]--set KEY=VALUE[/] on `lookalike track`.")
