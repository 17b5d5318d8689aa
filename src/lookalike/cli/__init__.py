"""The ``lookalike`` command line (typer). Each command lives in its own module of this package."""

from __future__ import annotations

from lookalike.cli import bench as _bench  # noqa: E402,F401
from lookalike.cli import bench_divers as _bench_divers  # noqa: E402,F401
from lookalike.cli import bench_experiments as _bench_experiments  # noqa: E402,F401
from lookalike.cli import bench_pixels as _bench_pixels  # noqa: E402,F401
from lookalike.cli import bench_real as _bench_real  # noqa: E402,F401
from lookalike.cli import demo as _demo  # noqa: E402,F401
from lookalike.cli import eval as _eval  # noqa: E402,F401
from lookalike.cli import label as _label  # noqa: E402,F401
from lookalike.cli import node as _node  # noqa: E402,F401
from lookalike.cli import render as _render  # noqa: E402,F401
from lookalike.cli import report as _report  # noqa: E402,F401
from lookalike.cli import simulate as _simulate  # noqa: E402,F401

# Importing the command modules registers their commands on ``app``.
from lookalike.cli import track as _track  # noqa: E402,F401
from lookalike.cli import train as _train  # noqa: E402,F401
from lookalike.cli import train_appearance as _train_appearance  # noqa: E402,F401
from lookalike.cli import tune as _tune  # noqa: E402,F401
from lookalike.cli import vision as _vision  # noqa: E402,F401
from lookalike.cli.app import app


def main() -> None:
    """Entry point of the ``lookalike`` script."""
    app()


__all__ = ["app", "main"]
