"""The typer application object shared by every command module."""

from __future__ import annotations

import os
import shlex
import sys
from collections.abc import Collection, Iterable, Iterator, Sequence
from contextlib import contextmanager
from pathlib import Path
from typing import TYPE_CHECKING, NoReturn

import typer
from rich.console import Console
from rich.markup import escape
from rich.text import Text
from typer._click import Context, HelpFormatter  # typer 0.29 vendors click (constraints.txt pins it)
from typer._click.globals import get_current_context
from typer.core import TyperGroup

from lookalike.cli.coercion import install
from lookalike.cli.program import run_as_program

if TYPE_CHECKING:
    from rich.table import Table

install()  # plain option values converted without pydantic (same values and errors as typer's)

if run_as_program():
    # Run as the program: FFmpeg's own lines on a truncated or damaged video (OpenCV's decoder prints them) would come
    # before lookalike's one-line error naming the video. A level the user set (e.g. 16 to see them) is kept.
    os.environ.setdefault("OPENCV_FFMPEG_LOGLEVEL", "-8")


class SortedGroup(TyperGroup):
    """A command group listing its commands alphabetically in ``--help``."""

    def list_commands(self, ctx: Context) -> list[str]:
        return sorted(super().list_commands(ctx))

    def format_commands(self, ctx: Context, formatter: HelpFormatter) -> None:
        """The commands with their whole first sentence, wrapped (click would cut it with '...')."""
        commands = [(name, self.get_command(ctx, name)) for name in self.list_commands(ctx)]
        rows = [(name, c.get_short_help_str(limit=10_000)) for name, c in commands if c is not None and not c.hidden]
        if rows:
            with formatter.section("Commands"):
                formatter.write_dl(rows)


app = typer.Typer(
    name="lookalike",
    cls=SortedGroup,
    rich_markup_mode=None,  # click's plain help: wraps cleanly at 80 columns
    help="Track and identify look-alike targets: robots, divers, animals.",
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_enable=False,
)
console = Console()
console.soft_wrap = not console.is_terminal  # piped or redirected: each message one line, however long
err_console = Console(stderr=True, soft_wrap=True)  # an error stays one line


def _version(value: bool) -> None:
    if value:
        from lookalike.io.results import lookalike_version

        console.print(f"lookalike {lookalike_version()}", highlight=False)
        raise typer.Exit()


@app.callback()
def _main(
    version: bool = typer.Option(False, "--version", callback=_version, is_eager=True,
                                 help="Print lookalike's version and exit."),
) -> None:
    """Track and identify look-alike targets: robots, divers, animals."""


def fail(message: str, code: int = 2) -> NoReturn:
    """Print ``message`` as an error, as plain text (markup-like input printed as given), and exit with ``code``."""
    err_console.print(Text.assemble(("error:", "bold red"), " ", message), highlight=False)
    raise typer.Exit(code)


@contextmanager
def failing(*errors: type[Exception], prefix: str = "") -> Iterator[None]:
    """Turn ``errors`` raised in the block into :func:`fail` with ``prefix`` and the error's text."""
    try:
        yield
    except errors as exc:
        fail(f"{prefix}{exc}")


def require(*modules: str) -> None:
    """Before any work or output: a missing optional package among ``modules`` ends the command in one line naming
    its extra (exit 2)."""
    import importlib

    from lookalike._optional import needs

    for module in modules:
        with needs(module):
            importlib.import_module(module)


def print_whole(table: Table) -> None:
    """Print a rich table wider than the console rather than cut a cell or squeeze a column below its
    ``min_width``."""
    size = Console(width=10_000).measure(table)
    (console if size.minimum <= console.width else Console(width=size.maximum)).print(table)


def check_names(option: str, names: list[str], known: Sequence[str], what: str) -> None:
    """Fail naming the first of ``names`` not in ``known``, or when there is none (an option given as ``,``)."""
    if not names:
        fail(f"{option}: no {what} given; known: {', '.join(known)}")
    for n in names:
        if n not in known:
            fail(f"{option}: unknown {what} {n!r}; known: {', '.join(known)}")


def check_teams(option: str, names: list[str]) -> None:
    """Fail naming the first of ``names`` that is no team (:func:`lookalike.sim.presets.team_size`), or when there is
    none."""
    from lookalike.sim.presets import TEAM_HELP, team_size

    if not names:
        fail(f"{option}: no team given; give {TEAM_HELP}")

    with failing(ValueError, prefix=f"{option}: "):
        for n in names:
            team_size(n)


def check_choice(option: str, value: str, choices: Sequence[str]) -> None:
    """Fail unless ``value`` is one of ``choices``."""
    if value not in choices:
        fail(f"{option}: expected one of {', '.join(choices)}, got {value!r}")


def warn(message: str) -> None:
    """Print ``message`` as a warning line (plain text) on stderr."""
    err_console.print(f"[yellow]warning:[/] {escape(message)}", highlight=False)


def note(message: str) -> None:
    """Print ``message`` as a note line (plain text) on stderr: what was assumed about an input."""
    err_console.print(f"[cyan]note:[/] {escape(message)}", highlight=False)


def check_outputs_or_fail(outputs: dict[str, Path | None], inputs: Iterable[Path | None] = (),
                          folders: Collection[str] = (), input_folders: Iterable[Path | None] = ()) -> None:
    """:func:`lookalike.io.outputs.check_outputs`, failing (exit 2) with its one line: run before any work."""
    from lookalike.io.outputs import check_outputs

    with failing(ValueError):
        check_outputs(outputs, inputs, folders=folders, input_folders=input_folders)


def check_study_or_fail(study: str | None) -> None:
    """Open an Optuna ``--study`` storage URL once before any work: fail (exit 2) in one line when optuna cannot."""
    if study is None:
        return
    from lookalike._optional import needs

    try:
        with needs("optuna"):
            import optuna
        optuna.storages.get_storage(study)
    except Exception as exc:  # noqa: BLE001 (optuna and sqlalchemy raise many kinds; each becomes one line)
        fail(f"--study {study}: {str(exc).splitlines()[0] if str(exc) else type(exc).__name__}")


def sequence_files(path: Path) -> list[Path]:
    """The files of the sequences at ``path``; none where it holds none (the command names that problem itself)."""
    from lookalike.io import find_sequences
    from lookalike.io.outputs import sequence_inputs

    try:
        return sequence_inputs(find_sequences(path))
    except (FileNotFoundError, ValueError):
        return []


def split_list(values: list[str] | None) -> list[str]:
    """Option values given repeated and/or comma-separated, as one list (blanks and repeats dropped: a data set,
    set-up or tracker named twice would run and count twice)."""
    return list(dict.fromkeys(v.strip() for item in values or [] for v in item.split(",") if v.strip()))


def command_line() -> str:
    """The command line being run, for a results file's header: ``sys.argv`` when run as the program, else the
    command path and its non-default options."""
    if run_as_program():
        return shlex.join(["lookalike", *sys.argv[1:]])
    ctx = get_current_context(silent=True)
    if ctx is None:
        return "lookalike"
    words = ctx.command_path.split()
    for param in ctx.command.params:
        value = ctx.params.get(param.name or "")
        if value is None or value == param.default or param.param_type_name != "option":
            continue
        flag = param.opts[0]
        if isinstance(value, bool):
            words.append(flag if value else (param.secondary_opts or [flag])[0])
        else:
            words += [w for v in (value if isinstance(value, (list, tuple)) else [value]) for w in (flag, str(v))]
    return shlex.join(words)
