"""Temporary files beside an output, with the mode a file created by ``open()`` gets: the one helper of every layer
that writes a file through a rename (:mod:`lookalike.io.outputs` for the outputs of the commands, the weights of
:mod:`lookalike.trackers.parts.weights_io`)."""

from __future__ import annotations

import os
import tempfile
from pathlib import Path


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
