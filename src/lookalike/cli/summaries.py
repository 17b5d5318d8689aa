"""The first paragraph of each command's help, read from the command modules' source, so that ``lookalike --help``
lists the commands without importing their modules."""

from __future__ import annotations

import inspect
import re
from pathlib import Path

_COMMAND = re.compile(r'^@app\.command\((?:"([\w-]+)")?\)\ndef (\w+)\(.*?\) -> None:\n    """(.*?)"""', re.M | re.S)
_GROUP = re.compile(r'^(\w+) = typer\.Typer\(help="([^"]*)".*?^app\.add_typer\(\1, name="([\w-]+)"\)', re.M | re.S)


def summaries(modules: tuple[str, ...]) -> dict[str, str]:
    """Command name → the first paragraph of its help, for the commands and groups that ``modules`` register."""
    found = {}
    for module in modules:
        source = (Path(__file__).parent / f"{module}.py").read_text(encoding="utf-8")
        for name, function, doc in _COMMAND.findall(source):
            found[name or function.replace("_", "-")] = inspect.cleandoc(doc).split("\n\n")[0]
        found.update({name: summary for _, summary, name in _GROUP.findall(source)})
    return found
