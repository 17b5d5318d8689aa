"""Progress bars: :func:`bars` on standard output, and :func:`progress_bars` for the long commands (``bench ...``,
``tune``), drawn on stderr with time left and only when it is a terminal."""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager
from typing import TYPE_CHECKING

from rich.console import Console
from rich.progress import (
    BarColumn,
    MofNCompleteColumn,
    Progress,
    ProgressColumn,
    TextColumn,
    TimeElapsedColumn,
    TimeRemainingColumn,
)

from lookalike.cli.app import console

if TYPE_CHECKING:
    from lookalike.bench.progress import ProgressFactory, Step

_stderr = Console(stderr=True)


def bars(label: str = "{task.description}", *more: ProgressColumn, transient: bool = True) -> Progress:
    """Rich progress on standard output: ``label``, the bar, done/total and time elapsed, then ``more`` columns."""
    return Progress(TextColumn(label), BarColumn(), MofNCompleteColumn(), TimeElapsedColumn(), *more,
                    console=console, transient=transient)


@contextmanager
def progress_bars() -> Iterator[ProgressFactory]:
    """A progress factory drawing rich bars (done/total, elapsed, time left) on stderr while the block runs."""
    with Progress(TextColumn("{task.description}"), BarColumn(), MofNCompleteColumn(), TimeElapsedColumn(),
                  TextColumn("left"), TimeRemainingColumn(), console=_stderr, transient=True,
                  disable=not _stderr.is_terminal) as progress:
        def factory(description: str, total: int) -> Step:
            task = progress.add_task(description, total=max(int(total), 1))
            return lambda: progress.advance(task)

        yield factory


__all__ = ["bars", "progress_bars"]
