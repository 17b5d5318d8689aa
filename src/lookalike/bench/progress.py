"""Progress of long benches: ``step = progress("m3n2 jpda", total)`` once per stage, then ``step()`` per unit done."""

from __future__ import annotations

from collections.abc import Callable

Step = Callable[[], None]
ProgressFactory = Callable[[str, int], Step]


def no_progress(description: str, total: int) -> Step:
    """A progress factory that reports nothing."""
    del description, total
    return lambda: None


__all__ = ["ProgressFactory", "Step", "no_progress"]
