"""``lookalike trackers``: the registered trackers, one line each, and one tracker's parameters."""

from __future__ import annotations

import typer

from lookalike.cli.app import app, console, fail, print_whole
from lookalike.trackers.registry import tracker_class, tracker_names, tracker_parameters

WIDTH = 80
"""Characters per line of the compact listing."""


def summary(name: str) -> str:
    """The first line of tracker ``name``'s class docstring, without reST markup."""
    doc = (tracker_class(name).__doc__ or "").strip()
    return doc.splitlines()[0].replace("``", "").strip() if doc else ""


def compact_lines(names: list[str], width: int = WIDTH) -> list[str]:
    """One line per tracker (name, what it reads, what it is), each at most ``width`` characters (a long
    description is cut with an ellipsis), after a header line."""
    from lookalike.io.needs import input_kind

    rows = [(name, input_kind(name), summary(name)) for name in names]
    w_name = max([len("tracker")] + [len(r[0]) for r in rows]) + 2
    w_kind = max([len("input")] + [len(r[1]) for r in rows]) + 2
    lines = []
    for name, kind, text in [("tracker", "input", "description"), *rows]:
        line = f"{name:<{w_name}}{kind:<{w_kind}}{text}".rstrip()
        lines.append(line if len(line) <= width else line[: width - 1] + "…")
    return lines


def _details(name: str) -> None:
    from rich.table import Table

    table = Table(title=f"[bold]{name}[/]: {summary(name)}", title_justify="left", show_lines=False)
    for column in ("parameter", "type", "default", "allowed"):
        table.add_column(column, no_wrap=True)  # whole: what --set takes
    table.add_column("meaning", min_width=24)
    for p in tracker_parameters(name):
        table.add_row(p.name, p.type, repr(p.default), p.allowed(), p.doc)
    print_whole(table)
    console.print("Set any parameter with [bold]--set KEY=VALUE[/] on `lookalike track`.")


@app.command()
def trackers(
    names: bool = typer.Option(False, "--names", help="Print only the names, one per line."),
    details: str | None = typer.Option(None, "--details", metavar="NAME",
                                       help="Print one tracker's parameters with defaults, allowed values and "
                                            "meaning."),
) -> None:
    """List the registered trackers, one line each (what each reads, what it is); --details NAME gives one
    tracker's parameters."""
    if names and details is not None:
        fail(f"--names and --details {details}: give one (--names lists every name, --details one tracker's "
             "parameters)")
    if names:  # the names alone: no tracker module is imported
        typer.echo("\n".join(tracker_names()))
        return
    if details is not None:
        known = tracker_names()
        if details not in known:
            fail(f"unknown tracker {details!r}; registered: {', '.join(known)}")
        _details(details)
        return
    typer.echo("\n".join(compact_lines(tracker_names())))
    typer.echo("Parameters of one tracker: lookalike trackers --details NAME")
