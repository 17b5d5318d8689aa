"""Files written through a temporary file beside them, renamed into place, with the mode a file created by ``open()``
gets: the helpers of every layer that writes a file whole (:mod:`lookalike.io.outputs` for the outputs of the
commands; the weights, models and training logs of the lower layers, which may not import ``io``)."""

from __future__ import annotations

import os
import tempfile
from collections.abc import Callable
from pathlib import Path
from typing import BinaryIO


def user_mode() -> int:
    """The mode a new file gets from ``open()``: ``0o666`` less the process umask."""
    status = Path("/proc/self/status")
    try:
        for line in status.read_text().splitlines():
            if line.startswith("Umask:"):
                return 0o666 & ~int(line.split()[1], 8)
    except (OSError, ValueError, IndexError):
        pass
    mask = os.umask(0o022)  # no other way to read it; restored at once
    os.umask(mask)
    return 0o666 & ~mask


def temp_beside(path: Path) -> tuple[int, Path]:
    """A new temporary file beside ``path`` (same folder and suffix, so that ``os.replace`` is atomic), with the mode
    a file created by ``open()`` gets (:func:`user_mode`), not ``mkstemp``'s 0600."""
    fd, tmp = tempfile.mkstemp(prefix=f".{path.stem}.", suffix=f".tmp{path.suffix}", dir=path.parent)
    try:
        os.fchmod(fd, user_mode())
    except OSError:
        pass  # a file system without modes
    except BaseException:  # Ctrl-C or SIGTERM before the caller holds the file: it would be left behind
        os.close(fd)
        os.unlink(tmp)
        raise
    return fd, Path(tmp)


def write_bytes(target: Path, data: bytes) -> None:
    """Write ``data`` to ``target`` through :func:`replace_file`."""
    replace_file(target, lambda f: f.write(data))


def replace_file(target: Path, write: Callable[[BinaryIO], object]) -> None:
    """Call ``write`` on a new temporary file beside ``target`` and rename it onto ``target``: a killed or failed
    ``write`` leaves the old ``target`` whole and no temporary file behind."""
    fd, tmp = temp_beside(target)
    try:
        with os.fdopen(fd, "wb") as f:
            write(f)
        os.replace(tmp, target)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise
