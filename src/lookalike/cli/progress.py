"""Progress bars with time left for the long commands (``bench ...``, ``tune``), drawn on stderr and only when it is a
terminal: ``with progress_bars() as progress: ...``."""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager

from rich.console import Console
from rich.progress import (
    BarColumn,
    MofNCompleteColumn,
    Progress,
    TextColumn,
    TimeElapsedColumn,
    TimeRemainingColumn,
)

from lookalike.bench.progress import ProgressFactory, Step

_console = Console(stderr=True)


@contextmanager
def progress_bars(console: Console | None = None) -> Iterator[ProgressFactory]:
    """A progress factory drawing rich bars (done/total, elapsed, time left) while the block runs."""
    out = console or _console
    columns = (TextColumn("{task.description}"), BarColumn(), MofNCompleteColumn(), TimeElapsedColumn(),
               TextColumn("left"), TimeRemainingColumn())
    with Progress(*columns, console=out, transient=True, disable=not out.is_terminal) as bars:
        def factory(description: str, total: int) -> Step:
            task = bars.add_task(description, total=max(int(total), 1))
            return lambda: bars.advance(task)

        yield factory


__all__ = ["progress_bars"]
