"""The input rules every reader in :mod:`lookalike.io` applies (frame numbers are integers >= 1 that jump past the
largest so far by at most ``max(MIN_GAP, GAP_FACTOR × that frame)`` unless a length bounds them), and temporary files
with the user's umask."""

from __future__ import annotations

import bz2
import codecs
import gzip
import lzma
import os
import stat
import zlib
from pathlib import Path
from types import ModuleType
from typing import TextIO

import numpy as np

from lookalike._files import temp_beside, user_mode

MIN_GAP = 10_000  # frames: a jump up to this is always allowed
GAP_FACTOR = 10  # ... and up to this times the largest frame number seen before it
COMPRESSIONS: tuple[tuple[bytes, ModuleType, str], ...] = (
    (b"\x1f\x8b", gzip, "gzip"), (b"BZh", bz2, "bzip2"), (b"\xfd7zXZ\x00", lzma, "xz"))
"""The first bytes of a compressed file, the module that reads it and the name of its format."""
DECOMPRESS_ERRORS = (OSError, EOFError, ValueError, zlib.error, lzma.LZMAError)
"""What reading a damaged or truncated compressed file raises."""


def _compression(head: bytes) -> tuple[ModuleType, str] | None:
    """The module and format name of a file beginning with ``head``, None for an uncompressed one."""
    return next(((module, name) for magic, module, name in COMPRESSIONS if head.startswith(magic)), None)


def not_a_file(path: Path) -> FileNotFoundError:
    """The error for reading ``path`` that is no file: a folder, or nothing."""
    return FileNotFoundError(f"{path}: {'is a folder, not a file' if path.is_dir() else 'no such file'}")


def read_text(path: str | os.PathLike[str]) -> str:
    """The UTF-8 text of ``path`` (a leading byte order mark dropped, as Windows editors and spreadsheets write one;
    UTF-16 with its byte order mark, as Windows PowerShell's ``>`` writes, read too; a gzip-, bzip2- or
    xz-compressed file decompressed); ``FileNotFoundError``/``ValueError`` naming the file otherwise."""
    path = Path(path)
    if not path.is_file():
        raise not_a_file(path)
    try:
        data = path.read_bytes()
    except OSError as exc:
        raise ValueError(f"{path}: cannot read ({exc.strerror or exc})") from None
    compressed = _compression(data[:6])
    if compressed is not None:
        try:
            data = compressed[0].decompress(data)
        except DECOMPRESS_ERRORS as exc:
            raise ValueError(f"{path}: a damaged or truncated {compressed[1]} file ({exc})") from None
    encoding = _encoding(data[:2])
    try:
        text = data.decode(encoding)
    except UnicodeDecodeError as exc:
        line = data.count(b"\n", 0, exc.start) + 1
        raise ValueError(f"{path}:{line}: not {'UTF-16' if encoding == 'utf-16' else 'UTF-8'} text (byte "
                         f"0x{data[exc.start]:02x}); expected a text file") from None
    nul = text.find("\0")
    if nul >= 0:
        raise ValueError(f"{path}:{text.count(chr(10), 0, nul) + 1}: not UTF-8 text (a NUL character: UTF-16 without "
                         "its byte order mark, or a binary file?); expected a text file")
    return text


def _encoding(head: bytes) -> str:
    """The encoding of text beginning with ``head``: UTF-16 after its byte order mark, else UTF-8 (with or without
    one)."""
    return "utf-16" if head[:2] in (codecs.BOM_UTF16_LE, codecs.BOM_UTF16_BE) else "utf-8-sig"


def is_data_line(line: str) -> bool:
    """Whether a line of a text input holds data: not blank, not a ``#`` comment."""
    text = line.strip()
    return bool(text) and not text.startswith("#")


def without_comment(line: str) -> str:
    """``line`` up to a ``#`` (a comment after the values, as numpy's reader also drops)."""
    return line.split("#", 1)[0]


def open_text(path: Path, errors: str = "strict") -> TextIO:
    """``path`` opened as UTF-8 text to read line by line, as :func:`read_text` reads it (a byte order mark dropped,
    a compressed file decompressed); ``errors`` as :func:`open`'s. Reading a damaged compressed file raises one of
    :data:`DECOMPRESS_ERRORS`."""
    with open(path, "rb") as fh:
        head = fh.read(6)
    compressed = _compression(head)
    if compressed is not None:
        stream: TextIO = compressed[0].open(path, "rt", encoding="utf-8-sig", errors=errors)
        return stream
    return open(path, encoding=_encoding(head), errors=errors)


def frame_problems(frames: np.ndarray, previous_max: float = 0.0, length: int | None = None,
                   length_name: str = "the length") -> tuple[int, str] | None:
    """``(index, reason)`` of the first frame number in ``frames`` (file order, 1-based) that breaks the rules, else
    None; ``previous_max``: the largest frame before these (streaming)."""
    frames = np.asarray(frames, dtype=float)
    if not len(frames):
        return None
    finite = np.isfinite(frames)
    bad_int = ~finite | (frames < 1) | (np.floor(np.where(finite, frames, 0)) != np.where(finite, frames, 1))
    bad_len = finite & (frames > length) if length is not None else np.zeros(len(frames), bool)
    if length is None:
        before = np.maximum.accumulate(np.concatenate([[previous_max], np.where(finite, frames, 0)]))[:-1]
        bad_gap = finite & (frames - before > np.maximum(MIN_GAP, GAP_FACTOR * before))
    else:
        bad_gap = np.zeros(len(frames), bool)
    bad = bad_int | bad_len | bad_gap
    if not bad.any():
        return None
    i = int(np.flatnonzero(bad)[0])
    f = frames[i]
    if bad_int[i]:
        return i, f"frame {f:g} is not an integer >= 1"
    if bad_len[i]:
        return i, f"frame {int(f)} > {length} ({length_name})"
    prev = int(before[i])
    return i, (f"frame {int(f)} jumps {int(f) - prev} frames past frame {prev} (at most "
               f"max({MIN_GAP}, {GAP_FACTOR} x {prev}) allowed; is the frame number a typo?)")


def write_target(path: Path) -> Path:
    """Where writing ``path`` lands: the file a symbolic link points at (the link stays a link), else ``path``."""
    return Path(os.path.realpath(path)) if path.is_symlink() else path


def is_special(path: Path) -> bool:
    """Whether ``path`` is a device, named pipe or socket (``/dev/null``): written into directly, since renaming a
    finished temporary file onto it would replace it."""
    try:
        mode = os.stat(path).st_mode
    except OSError:
        return False
    return not (stat.S_ISREG(mode) or stat.S_ISDIR(mode))


__all__ = ["COMPRESSIONS", "DECOMPRESS_ERRORS", "GAP_FACTOR", "MIN_GAP", "frame_problems", "is_data_line", "is_special",
           "not_a_file", "open_text", "read_text", "temp_beside", "user_mode", "without_comment",
           "write_target"]
