"""MOTChallenge text files: ``frame, id, left, top, width, height, conf, x, y, z[, ...]``, frames 1-based (kept so in
``MotTable.frame``; :func:`frames_from_table` yields 0-based :class:`Frame` objects)."""

from __future__ import annotations

import math
import os
import warnings
from collections.abc import Iterable, Iterator
from pathlib import Path

import numpy as np

from lookalike.io.rules import (
    DECOMPRESS_ERRORS,
    GAP_FACTOR,
    MIN_GAP,
    frame_problems,
    is_data_line,
    not_a_file,
    open_text,
    read_text,
    without_comment,
)
from lookalike.types import Detections, Frame
from lookalike.types.mot_table import ROW_WIDTH, MotTable, stack_rows, table_from_array, tracks_to_rows

_ROW_FORMAT = "%d,%d,%.3f,%.3f,%.3f,%.3f,%g,%g,%g,%g\n"
_FORMAT_BLOCK = 4096
_COLUMNS = "columns: frame,id,left,top,width,height,score[,x,y,z]"
MAX_ID = 2**53  # beyond this a number read as a float no longer tells neighbouring ids apart


def read_mot(path: str | os.PathLike[str], min_columns: int = 6, length: int | None = None,
             length_name: str = "the length", positive_size: bool = False) -> MotTable:
    """Read a MOTChallenge text file (UTF-8; blank and ``#`` comment lines skipped); ``ValueError`` naming the file
    and line of a malformed one: too few columns, a non-number, NaN or infinity in frame, id, box or score, an id not
    whole, a negative size (zero too with ``positive_size``), or a frame number breaking :mod:`lookalike.io.rules` or
    past ``length``. ``min_columns``: at least 6 (frame, id and the box)."""
    if not (isinstance(min_columns, int) and min_columns >= 6):
        raise ValueError(f"min_columns must be a whole number >= 6 (frame, id and the box), got {min_columns!r}")
    path = Path(path)
    if not path.is_file():
        raise not_a_file(path)
    fast = _parse_fast(path, min_columns)
    if fast is not None and row_problem(fast, length=length, positive_size=positive_size) is None:
        return table_from_array(fast, path)
    rows = [(i + 1, ln) for i, ln in enumerate(read_text(path).splitlines()) if is_data_line(ln)]
    if not rows:
        return table_from_array(np.zeros((0, 7)), path)
    data = _parse_slowly(path, rows, min_columns)
    problem = row_problem(data, length=length, length_name=length_name, positive_size=positive_size)
    if problem is not None:
        line_no, line = rows[problem[0]]
        raise ValueError(f"{path}:{line_no}: {problem[1]}: {line.strip()[:80]!r}")
    return table_from_array(data, path)


def row_problem(data: np.ndarray, previous_max: float = 0.0, length: int | None = None,
                length_name: str = "the length", positive_size: bool = False) -> tuple[int, str] | None:
    """``(row, reason)`` of the first row of ``data`` ``(k, c)`` that :func:`read_mot` refuses, else None."""
    if not len(data) or _rows_fine(data, previous_max, length, positive_size):
        return None
    box = ~np.isfinite(data[:, 1:7]).all(axis=1)
    size = ((data[:, 4:6] <= 0) if positive_size else (data[:, 4:6] < 0)).any(axis=1)
    size_reason = "invalid box: zero or negative width or height" if positive_size else \
        "invalid box: negative width or height"
    frame = frame_problems(data[:, 0], previous_max, length, length_name)
    ids = np.where(box, 0.0, data[:, 1])
    fraction = np.floor(ids) != ids  # (an id is a whole number: 1.2 and 1.7 are not one track, nor two)
    huge = np.abs(ids) > MAX_ID
    first = [(int(np.flatnonzero(box)[0]), "NaN or infinity in frame, id, box or score") if box.any() else None,
             (int(np.flatnonzero(fraction)[0]), "invalid id: not a whole number") if fraction.any() else None,
             (int(np.flatnonzero(huge)[0]), f"invalid id: beyond ±2^53 = {MAX_ID}, where ids are no longer told apart")
             if huge.any() else None,
             (int(np.flatnonzero(size)[0]), size_reason) if size.any() else None,
             (frame[0], f"invalid frame: {frame[1]}") if frame is not None else None]
    found = [p for p in first if p is not None]
    return min(found, key=lambda p: p[0]) if found else None


def _rows_fine(data: np.ndarray, previous_max: float, length: int | None, positive_size: bool) -> bool:
    """True when no row breaks a rule of :func:`row_problem`, from whole-table reductions (False: look closer)."""
    with np.errstate(over="ignore", invalid="ignore"):
        total = data[:, 1:7].sum()
    if not np.isfinite(total):  # a NaN or infinity makes the sum one (a huge sum only looks like one)
        return False
    sizes = data[:, 4:6].min()
    if not (sizes > 0 if positive_size else sizes >= 0):
        return False
    if not ((np.floor(data[:, 1]) == data[:, 1]).all() and np.abs(data[:, 1]).max() <= MAX_ID):
        return False
    frames = data[:, 0]
    first, last = float(frames.min()), float(frames.max())
    if not (np.isfinite(first) and np.isfinite(last) and first >= 1 and (np.floor(frames) == frames).all()):
        return False
    if length is not None:
        return last <= length
    # every frame's jump past the frames before it is at most last - previous_max, and its bound at least this
    return last - previous_max <= max(MIN_GAP, GAP_FACTOR * previous_max)


def _parse_fast(path: Path, min_columns: int) -> np.ndarray | None:
    """numpy's C parser for regular files; None when anything needs a closer look."""
    try:  # (opened here: numpy would pick a decompressor by the name's suffix, .gz, .bz2, .xz, not the content)
        with warnings.catch_warnings(), open_text(path) as fh:
            warnings.simplefilter("ignore")  # an empty file warns
            data = np.loadtxt(fh, delimiter=",", ndmin=2)
    except (ValueError, *DECOMPRESS_ERRORS):
        return None  # (the careful parser names the problem)
    if data.shape[0] == 0:
        return np.zeros((0, 7)) if not read_text(path).strip() else None
    if data.shape[1] < min_columns:
        return None
    return data


def _parse_slowly(path: Path, rows: list[tuple[int, str]], min_columns: int) -> np.ndarray:
    parsed: list[list[float]] = []
    width = None
    for line_no, line in rows:
        fields = [f.strip() for f in without_comment(line).split(",")]
        while len(fields) > max(min_columns, 7) and not fields[-1]:
            fields.pop()  # a trailing comma, or x, y, z left empty: the optional columns are absent
        if len(fields) < min_columns:
            raise ValueError(
                f"{path}:{line_no}: expected at least {min_columns} comma-separated columns, "
                f"got {len(fields)}: {line.strip()!r} ({_COLUMNS})"
            )
        try:
            values = [float(f) for f in fields]
        except ValueError:
            column = next(k for k, f in enumerate(fields, 1) if not _is_number(f))
            what = "is empty" if not fields[column - 1] else f"is not a number ({fields[column - 1][:20]!r})"
            raise ValueError(f"{path}:{line_no}: column {column} {what} in {line.strip()[:80]!r} ({_COLUMNS})") \
                from None
        width = len(values) if width is None else min(width, len(values))
        parsed.append(values)
    return np.array([v[:width] for v in parsed], dtype=float)


def _is_number(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True


def frames_from_table(
    table: MotTable, length: int | None = None, frame_rate: float = 30.0, min_score: float = -np.inf
) -> Iterator[Frame]:
    """One :class:`Frame` per frame ``0 .. length-1`` (file frame ``k`` is index ``k-1``; ``time = index /
    frame_rate``), boxes scored below ``min_score`` dropped. ``ValueError`` for a ``frame_rate`` that is not a finite
    number above 0 (frames per second), a ``length`` that is not a whole number >= 0, or a NaN ``min_score``."""
    if not (math.isfinite(frame_rate) and frame_rate > 0):
        raise ValueError(f"frame_rate must be a finite number above 0 (frames per second), got {frame_rate}")
    if length is not None and not (isinstance(length, (int, np.integer)) and length >= 0):
        raise ValueError(f"length must be a whole number of frames >= 0, got {length!r}")
    if math.isnan(min_score):
        raise ValueError("min_score must be a number, got nan")
    if length is None:
        length = int(table.frame.max()) if len(table) else 0
    keep = table.conf >= min_score
    frames = table.frame[keep]
    order = np.argsort(frames, kind="stable")
    frames = frames[order]
    xywh, conf = table.xywh[keep][order], table.conf[keep][order]
    bounds = np.searchsorted(frames, np.arange(1, length + 2))
    for index in range(length):
        lo, hi = bounds[index], bounds[index + 1]
        yield Frame(index=index, time=index / frame_rate, detections=Detections(xywh=xywh[lo:hi], score=conf[lo:hi]))


def write_mot(path: str | os.PathLike[str], rows: Iterable[np.ndarray] | np.ndarray) -> Path:
    """Write result rows ``(n, 10)`` (or blocks of them) atomically: a failure never leaves a half-written file.
    ``ValueError`` naming ``path`` for another shape or a row :func:`read_mot` would refuse; nothing is written."""
    from lookalike.io.outputs import write_atomic

    try:
        data = stack_rows([rows] if isinstance(rows, np.ndarray) else rows)
    except ValueError as exc:
        raise ValueError(f"{path}: {exc}; nothing written") from None
    problem = row_problem(data)
    if problem is not None:
        raise ValueError(f"{path}: the row of frame {data[problem[0], 0]:g}: {problem[1]}; nothing written")
    return write_atomic(path, format_rows(data))


def format_rows(rows: np.ndarray) -> str:
    """Result rows ``(k, >= 10)`` as MOTChallenge lines: frame and id as integers, boxes to 1/1000 px, the other
    four columns as ``%g``, each line ending in a newline."""
    data = np.asarray(rows, dtype=float)
    if data.ndim != 2 or data.shape[1] < ROW_WIDTH:
        raise ValueError(f"result rows need shape (k, {ROW_WIDTH}) or wider, got {data.shape}")
    data = data[:, :ROW_WIDTH]
    parts = []
    for start in range(0, len(data), _FORMAT_BLOCK):
        block = data[start:start + _FORMAT_BLOCK]
        parts.append((_ROW_FORMAT * len(block)) % tuple(block.ravel().tolist()))
    return "".join(parts)


__all__ = ["MAX_ID", "MotTable", "format_rows", "frames_from_table", "read_mot", "tracks_to_rows", "write_mot"]
