"""Progress reporting for long benches, without a dependency on any display.

A bench function takes ``progress: ProgressFactory`` and calls ``step = progress("m3n2 jpda", total)`` once per stage,
then ``step()`` once per unit done (a sequence, a frame, a job). The command line passes
:func:`lookalike.cli.progress.progress_bars` (rich bars with time left); the default :func:`no_progress` does nothing.
"""

from __future__ import annotations

from collections.abc import Callable

Step = Callable[[], None]
ProgressFactory = Callable[[str, int], Step]


def _nothing() -> None:
    return None


def no_progress(description: str, total: int) -> Step:
    """A progress factory that reports nothing."""
    del description, total
    return _nothing


__all__ = ["ProgressFactory", "Step", "no_progress"]
