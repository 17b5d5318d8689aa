"""``lookalike track``'s last step, printed: :mod:`lookalike.pipeline.results` adds each result row's identity
confidence; the doubtful ranges are printed."""

from __future__ import annotations

from pathlib import Path

from rich.markup import escape

from lookalike.cli.app import console
from lookalike.pipeline import results
from lookalike.pipeline.results import written_results


def add_confidence(found: list[tuple[Path, float]]) -> None:
    """:func:`lookalike.pipeline.results.add_confidence`, one line of doubtful ranges printed per file."""
    for line in results.add_confidence(found):
        console.print(escape(line), highlight=False)


__all__ = ["add_confidence", "written_results"]
