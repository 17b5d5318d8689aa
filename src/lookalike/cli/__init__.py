"""The ``lookalike`` command line (typer), a module per command; run as the program, only the module of the command
given is imported (:data:`COMMAND_MODULES`)."""

from __future__ import annotations

import importlib
import os
import sys

from rich.markup import escape

from lookalike.cli.program import run_as_program

if run_as_program():
    # before numpy loads: lookalike's matrices are small, so OpenBLAS's threads only cost (a value set is kept)
    os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

from lookalike.cli.app import app  # noqa: E402

MODULES = ("bench", "bench_divers", "bench_experiments", "bench_pixels", "bench_real", "demo", "eval", "label",
           "node", "proofread", "record_pixels", "render", "report", "simulate", "track", "track_pixels", "trackers",
           "train", "train_appearance", "tune", "vision")
"""Every command module, in the order they are imported."""

COMMAND_MODULES = ("track", "trackers", "eval", "simulate", "render", "report", "demo", "label", "proofread")
"""Commands whose module (of the same name) alone is imported when the script runs them."""


def _script_command() -> str | None:
    """The command the ``lookalike`` script is running, or None (imported as a library, or no command)."""
    if not run_as_program():
        return None
    return next((a for a in sys.argv[1:] if not a.startswith("-")), None)


def _list_commands_only() -> None:
    """Register each command by name and summary alone: the script was given no command (``lookalike --help``)."""
    from lookalike.cli.summaries import summaries

    def listed_only() -> None:  # never runs: a command given on the line loads its module instead
        raise AssertionError("a listed-only command was run")

    for name, summary in summaries(MODULES).items():
        app.command(name=name, help=summary)(listed_only)


def _load_commands() -> None:
    command = _script_command()
    if command is None and run_as_program():
        _list_commands_only()
        return
    for name in (command,) if command in COMMAND_MODULES else MODULES:
        importlib.import_module(f"lookalike.cli.{name}")


_load_commands()


def _terminate_cleanly() -> None:
    """SIGTERM raises ``SystemExit(143)`` in this process (forked workers keep the default): the ``finally`` blocks
    run, so no half-written output is left."""
    import signal

    pid = os.getpid()

    def handler(signum: int, frame: object) -> None:
        if os.getpid() != pid:  # a forked worker: die as before
            signal.signal(signum, signal.SIG_DFL)
            os.kill(os.getpid(), signum)
            return
        raise SystemExit(128 + signum)

    signal.signal(signal.SIGTERM, handler)


def main() -> None:
    """Entry point of the ``lookalike`` script; a missing optional package ends it with one line (exit 2)."""
    from lookalike import _compiled
    from lookalike._optional import MissingExtra

    _compiled.compile_aside = True  # kernels not cached yet compile in another process, not in this run
    _terminate_cleanly()
    try:
        app()
    except MissingExtra as exc:
        from lookalike.cli.app import err_console

        command = _script_command()
        where = f"lookalike {command}" if command else "lookalike"
        err_console.print(f"[bold red]error:[/] {escape(where)}: {escape(str(exc))}", highlight=False)
        raise SystemExit(2) from None


__all__ = ["app", "main"]
