"""The typer application object shared by every command module."""

from __future__ import annotations

from typing import NoReturn

import typer
from rich.console import Console

app = typer.Typer(
    name="lookalike",
    help="Track and identify look-alike targets: robots, divers, animals.",
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_enable=False,
)
console = Console()
err_console = Console(stderr=True, soft_wrap=True)  # an error stays one line


def fail(message: str, code: int = 2) -> NoReturn:
    """Print ``message`` as an error and exit with ``code``."""
    err_console.print(f"[bold red]error:[/] {message}")
    raise typer.Exit(code)


def split_list(values: list[str] | None) -> list[str]:
    """Option values given repeated and/or comma-separated, as one list (blanks dropped)."""
    return [v.strip() for item in values or [] for v in item.split(",") if v.strip()]
