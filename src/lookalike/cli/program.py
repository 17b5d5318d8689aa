"""Whether this process is the ``lookalike`` program (the console script or ``python -m lookalike``), not a library
user, a test runner or another ``python -m`` module."""

from __future__ import annotations

import sys
from pathlib import Path


def run_as_program() -> bool:
    """True for the ``lookalike`` script and for ``python -m lookalike`` (``sys.argv[0]`` is its ``__main__.py``)."""
    if not sys.argv:
        return False
    first = Path(sys.argv[0])
    return first.name == "lookalike" or (first.name == "__main__.py" and first.parent.name == "lookalike")
