"""mkdocs hook: the CLI reference, generated at build time from the typer application.

A page containing the line ``<!-- cli-reference -->`` gets, in its place, the Markdown that typer's
own documentation generator (``typer.cli.get_docs_for_click``, what ``typer ... utils docs`` prints)
makes from ``lookalike.cli.app``: every command and sub-command with its usage, arguments and
options. Any error (an import that fails, a command that cannot be rendered) fails the build.
"""

from __future__ import annotations

from typing import Any

MARKER = "<!-- cli-reference -->"


def cli_markdown(heading_level: int = 2) -> str:
    """The reference of every ``lookalike`` command as Markdown, top heading at ``heading_level``."""
    import typer
    import typer.main
    from typer.cli import get_docs_for_click

    from lookalike.cli import app

    command = typer.main.get_command(app)
    ctx = typer.Context(command, info_name="lookalike", obj={})
    text = get_docs_for_click(obj=command, ctx=ctx, name="lookalike", indent=heading_level - 1)
    return text.strip() + "\n"


def on_page_markdown(markdown: str, page: Any, config: Any, files: Any) -> str:  # noqa: ARG001
    """Replace the marker line with the generated reference."""
    if MARKER not in markdown:
        return markdown
    return markdown.replace(MARKER, cli_markdown())
