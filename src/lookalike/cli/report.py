"""``lookalike report``: one self-contained HTML report from ``eval``/``bench`` JSON outputs."""

from __future__ import annotations

import tempfile
from pathlib import Path

import typer

from lookalike.cli.app import app, check_outputs_or_fail, console, failing
from lookalike.viz.report import HtmlReport
from lookalike.viz.results import add_results, load_results


@app.command()
def report(
    results: list[Path] = typer.Argument(..., help="JSON files from `lookalike eval --json` or any `bench ... "
                                                   "--json` (or the demo's robots-ident.json/divers.json); charts "
                                                   "for eval, bench ident and bench divers."),
    output: Path = typer.Option(Path("report.html"), "-o", "--output", help="HTML file to write."),
    title: str = typer.Option("lookalike results", help="Title of the report."),
) -> None:
    """Build an HTML report (tables and bar charts, images embedded) from result files."""
    check_outputs_or_fail({"-o/--output": output}, results)
    doc = HtmlReport(title)
    with failing(ValueError):
        loaded = [(p, *load_results(p)) for p in results]
        with tempfile.TemporaryDirectory() as tmp:
            for i, (path, kind, rows) in enumerate(loaded):
                try:
                    add_results(doc, kind, rows, Path(tmp), f"chart{i}", title=f"{path.name}")
                except (TypeError, KeyError, AttributeError, IndexError, ValueError) as exc:  # a value's wrong type
                    if isinstance(exc, ValueError) and str(exc).startswith("results:"):
                        raise
                    raise ValueError(f"results: {path}: unexpected content ({type(exc).__name__}: "
                                     f"{str(exc)[:80]})") from None
            out = doc.write(output)
    console.print(f"wrote {out} ({len(loaded)} result file(s))", markup=False)
