"""Progress bars: :func:`bars` on standard output, and :func:`progress_bars` for the long commands (``bench ...``,
``tune``), drawn on stderr with time left and only when it is a terminal."""

from __future__ import annotations

from collections.abc import Callable, Iterator
from contextlib import ExitStack, contextmanager
from typing import TYPE_CHECKING, Any

from rich.console import Console
from rich.markup import escape
from rich.progress import (
    BarColumn,
    MofNCompleteColumn,
    Progress,
    ProgressColumn,
    TextColumn,
    TimeElapsedColumn,
    TimeRemainingColumn,
)
from rich.status import Status

from lookalike.cli.app import console, note, warn

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


@contextmanager
def printed_events() -> Iterator[Callable[[Any], None]]:
    """An ``on_event`` for :func:`lookalike.pipeline.run`: notes, warnings and lines printed, a result after its
    tracker's name in green, steps drawn as bars while any is on (a spinner for a step that tells no progress)."""
    with ExitStack() as stack:
        tasks: dict[str, Any] = {}
        progress = ExitStack()
        stack.push(progress)
        bar: list[Progress] = []

        def on_event(event: Any) -> None:
            kind, text = event.kind, event.text
            if kind == "busy" and (event.name or text) in tasks:
                tasks[event.name or text].update(escape(text))
            elif kind == "busy":
                tasks[event.name or text] = console.status(escape(text))
                tasks[event.name or text].start()
                stack.callback(tasks[event.name or text].stop)
            elif kind == "start":
                bar[:] = bar or [progress.enter_context(bars())]
                tasks[text] = bar[0].add_task(text, total=event.count or None)
            elif kind == "advance":
                bar[0].advance(tasks[text], event.count)
            elif kind == "end":
                task = tasks.pop(text)
                task.stop() if isinstance(task, Status) else bar[0].remove_task(task)
                if bar and not bar[0].task_ids:
                    progress.close()
                    bar.clear()
            elif kind in ("note", "warn"):
                (note if kind == "note" else warn)(text)
            elif kind == "result":
                console.print(f"[green]{escape(event.name)}[/]" + escape(text))
            else:
                console.print(text, markup=False)

        yield on_event


__all__ = ["bars", "printed_events", "progress_bars"]
