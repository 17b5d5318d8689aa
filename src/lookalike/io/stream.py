"""Streaming MOTChallenge input (:class:`DetectionStream`) and output (:class:`MotWriter`) for
:func:`lookalike.loop.run`."""

from __future__ import annotations

import itertools
import os
import warnings
from collections.abc import Iterable, Iterator
from pathlib import Path
from types import TracebackType
from typing import Any, TextIO

import numpy as np

from lookalike.io.det_format import box_stats, largest_side, read_det, sniff_det
from lookalike.io.motchallenge import format_rows, frames_from_table, read_mot, row_problem
from lookalike.io.rules import DECOMPRESS_ERRORS, is_special, not_a_file, open_text, temp_beside, write_target
from lookalike.io.sequences import MotSequence
from lookalike.loop import RunStats, Sink, Sinks, Updating, run
from lookalike.types import Detections, Frame
from lookalike.types.mot_table import ROW_WIDTH, MotTable, tracks_to_rows

CHUNK_LINES = 8_192
WRITE_ROWS = 4_096
"""Result rows a :class:`MotWriter` holds before formatting and writing them as one block."""


def _chunks(path: Path, lines: int) -> Iterator[np.ndarray]:
    """The file's rows ``(k, c)``, ``lines`` lines at a time (``ValueError`` for anything numpy cannot parse)."""
    with open_text(path) as fh:
        while True:
            block = list(itertools.islice(fh, lines))
            if not block:
                return
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")  # a block of blank lines warns
                data = np.loadtxt(block, delimiter=",", ndmin=2)
            if data.size:
                yield data


class DetectionStream:
    """The frames of a MOTChallenge detection file, checked whole in chunks first (:func:`~lookalike.io.read_mot`'s
    errors), then parsed a chunk at a time (irregular files read whole); frames equal
    :func:`~lookalike.io.frames_from_table`'s. ``length``: frames (None: the file's last); ``length_name`` names it
    in errors; ``image_size`` ``(width, height)`` px: :meth:`check` counts boxes centred outside it."""

    def __init__(self, path: str | os.PathLike[str], length: int | None = None, frame_rate: float = 30.0,
                 min_score: float = -np.inf, chunk_lines: int = CHUNK_LINES, length_name: str = "the length",
                 image_size: tuple[int, int] | None = None) -> None:
        if not (np.isfinite(frame_rate) and frame_rate > 0):
            raise ValueError(f"frame_rate must be a positive number, got {frame_rate}")
        if length is not None and not (length >= 0 and length == int(length)):
            raise ValueError(f"length must be a whole number of frames >= 0, got {length}")
        self.path, self.length, self.frame_rate = Path(path), length, frame_rate
        self.min_score, self.chunk_lines, self.length_name = min_score, chunk_lines, length_name
        self._streamable: bool | None = None
        self._single: np.ndarray | None = None  # the parsed file when it fits one chunk
        self.rows = 0  # rows in the file (known after check())
        self.image_size = image_size
        self.scores: tuple[float, float] | None = None  # lowest and highest score (known after check())
        self.outside = 0  # boxes centred outside image_size (known after check())
        self.largest = 0.0  # the largest box width or height in px (known after check())
        self.notes: list[str] = []  # what was assumed about the file's layout (sequence_stream)
        self._table: MotTable | None = None  # rows read already (from_table)

    @classmethod
    def from_table(cls, table: MotTable, length: int | None = None, frame_rate: float = 30.0,
                   min_score: float = -np.inf, image_size: tuple[int, int] | None = None) -> DetectionStream:
        """The frames of detections read already (checked: :func:`~lookalike.io.det_format.read_det`)."""
        if table.path is None:
            raise ValueError("table: a DetectionStream needs the file a table was read from (read_det or read_mot); "
                             "frames_from_table streams a table built in memory")
        stream = cls(table.path, length, frame_rate, min_score, image_size=image_size)
        stream._table, stream._streamable, stream.rows = table, False, len(table)
        stream.scores, stream.outside = box_stats(table.xywh, table.conf, image_size)
        stream.largest = largest_side(table.xywh)
        return stream

    def check(self) -> DetectionStream:
        """Read the file once (constant memory); raise ``ValueError`` / ``FileNotFoundError`` as
        :func:`~lookalike.io.read_mot` does for a malformed file (with ``length``). Returns ``self``."""
        if not self.path.is_file():
            raise not_a_file(self.path)
        last, width, rows = 0.0, None, 0
        self._single = None
        chunks: list[np.ndarray] = []
        low, high, outside, largest = np.inf, -np.inf, 0, 0.0
        try:
            for data in _chunks(self.path, self.chunk_lines):
                if len(chunks) < 2:
                    chunks.append(data)
                frames = data[:, 0]
                bad = (data.shape[1] < 6 or (width is not None and data.shape[1] != width)
                       or row_problem(data, last, self.length, positive_size=True) is not None
                       or frames[0] < last or (np.diff(frames) < 0).any())
                if bad:
                    raise ValueError
                width, last, rows = data.shape[1], float(frames[-1]), rows + len(data)
                scores, out = box_stats(data[:, 2:6], data[:, 6] if width > 6 else np.ones(len(data)),
                                        self.image_size)
                if scores is not None:
                    low, high, outside = min(low, scores[0]), max(high, scores[1]), outside + out
                largest = max(largest, largest_side(data[:, 2:6]))
            self._streamable, self.rows = True, rows
            self.scores, self.outside, self.largest = ((low, high) if rows else None), outside, largest
            if len(chunks) == 1:  # the whole file was one chunk: kept, not parsed again
                self._single = chunks[0]
        except (ValueError, *DECOMPRESS_ERRORS):
            # raises the precise error, or the file is valid but irregular (read whole)
            table = read_mot(self.path, length=self.length, length_name=self.length_name, positive_size=True)
            self.rows = len(table)
            self.scores, self.outside = box_stats(table.xywh, table.conf, self.image_size)
            self.largest = largest_side(table.xywh)
            self._streamable = False
        return self

    def __iter__(self) -> Iterator[Frame]:
        if self._streamable is None:
            self.check()
        if not self._streamable:
            table = self._table if self._table is not None else read_mot(self.path)
            yield from frames_from_table(table, self.length, self.frame_rate, self.min_score)
            return
        yield from self._stream()

    def _frame(self, index: int, xywh: np.ndarray, score: np.ndarray) -> Frame:
        return Frame(index=index, time=index / self.frame_rate, detections=Detections(xywh=xywh, score=score))

    def _stream(self) -> Iterator[Frame]:
        empty = self._frame  # frames without rows
        nxt = 0  # index of the next frame to yield
        pending: list[np.ndarray] = []  # rows of frame ``nxt`` seen so far (it may span chunks)
        end = self.length
        single, self._single = self._single, None  # a second pass parses the file again
        for data in [single] if single is not None else _chunks(self.path, self.chunk_lines):
            if end is not None:
                data = data[data[:, 0] <= end]
            if not len(data):
                continue
            frames = data[:, 0].astype(int) - 1  # 0-based, non-decreasing
            cuts = np.flatnonzero(np.diff(frames)) + 1
            for block in np.split(data, cuts):
                index = int(block[0, 0]) - 1
                if index > nxt:
                    if pending:
                        yield self._emit(nxt, pending)
                        pending, nxt = [], nxt + 1
                    while nxt < index:
                        yield empty(nxt, np.zeros((0, 4)), np.zeros(0))
                        nxt += 1
                pending.append(block)
        if pending:
            yield self._emit(nxt, pending)
            nxt += 1
        while end is not None and nxt < end:
            yield empty(nxt, np.zeros((0, 4)), np.zeros(0))
            nxt += 1

    def _emit(self, index: int, blocks: list[np.ndarray]) -> Frame:
        data = blocks[0] if len(blocks) == 1 else np.vstack(blocks)
        conf = data[:, 6].copy() if data.shape[1] > 6 else np.ones(len(data))
        keep = conf >= self.min_score
        return self._frame(index, data[keep, 2:6].copy(), conf[keep])


class MotWriter:
    """A sink for :func:`lookalike.loop.run` writing result rows to a temporary file that :meth:`close` renames to
    ``path``, or to the file a symbolic link ``path`` points at (leaving a ``with`` block on an exception deletes
    it). A device or named pipe (``/dev/null``) is written into directly. The file is made on entering the ``with``
    block (or at the first write), so nothing is left behind by a signal before it."""

    def __init__(self, path: str | os.PathLike[str]) -> None:
        self.path = Path(path)
        self._target = write_target(self.path)
        self._tmp: Path | None = None
        self._fh: TextIO | None = None  # (opened by __enter__ or the first write; closed by close or abort)
        self._ended = False
        if not is_special(self._target):
            self._target.parent.mkdir(parents=True, exist_ok=True)
        self._pending: list[np.ndarray] = []  # rows not yet written (at most WRITE_ROWS)
        self._pending_rows = 0
        self.rows = 0

    def __call__(self, frame: Frame, tracks: Any) -> None:
        self.write_rows(tracks_to_rows(frame.index, tracks))

    def _open(self) -> TextIO:
        """The file written to, opened at the first need (in ``__enter__``, not ``__init__``: a signal arriving between
        the two would leave the temporary file behind); ``ValueError`` once closed or aborted."""
        if self._ended:
            raise ValueError(f"{self.path}: writer already closed")
        if self._fh is None:
            if is_special(self._target):
                self._fh = open(self._target, "w")
            else:
                fd, self._tmp = temp_beside(self._target)
                try:
                    self._fh = os.fdopen(fd, "w")
                except BaseException:
                    os.close(fd)
                    self._tmp.unlink(missing_ok=True)
                    raise
        return self._fh

    def write_rows(self, rows: np.ndarray) -> None:
        """Append result rows ``(k, 10)`` (wider ones cut to 10 columns); ``ValueError`` for another shape, and (when
        written) for a NaN or infinite value, naming its frame."""
        self._open()
        block = np.array(rows, dtype=float)  # a copy: the caller may reuse its array
        if block.size == 0:
            return
        if block.ndim != 2 or block.shape[1] < ROW_WIDTH:
            raise ValueError(f"{self.path}: result rows need shape (k, {ROW_WIDTH}), got {block.shape}")
        self._pending.append(block[:, :ROW_WIDTH])
        self._pending_rows += len(block)
        if self._pending_rows >= WRITE_ROWS:
            self._flush()
        self.rows += len(block)

    def _flush(self) -> None:
        if self._fh is not None and self._pending:
            block = self._pending[0] if len(self._pending) == 1 else np.vstack(self._pending)
            bad = ~np.isfinite(block[:, :7]).all(axis=1)
            if bad.any():
                raise ValueError(f"{self.path}: the tracker produced a NaN or infinite box at frame "
                                 f"{block[bad][0, 0]:g} (from a degenerate detection?); nothing written")
            self._fh.write(format_rows(block))
        self._pending, self._pending_rows = [], 0

    def flush(self) -> None:
        """Write the rows held so far to the temporary file now (a live run: rows on disk as they come)."""
        self._flush()
        if self._fh is not None:
            self._fh.flush()

    def close(self) -> Path:
        """Finish the file: rename the temporary file to ``path``. Returns ``path``."""
        if not self._ended:
            fh = self._open()
            self._ended = True
            try:
                self._flush()
            except BaseException:
                self.abort()
                raise
            self._fh = None
            try:
                fh.close()
                if self._tmp is not None:
                    os.replace(self._tmp, self._target)
            except BaseException:
                if self._tmp is not None:
                    self._tmp.unlink(missing_ok=True)
                raise
        return self.path

    def abort(self) -> None:
        """Drop the temporary file; ``path`` is left as it was."""
        self._pending, self._pending_rows = [], 0
        self._ended = True
        if self._fh is not None:
            self._fh.close()
            self._fh = None
            if self._tmp is not None:
                self._tmp.unlink(missing_ok=True)

    def __enter__(self) -> MotWriter:
        try:
            self._open()
        except BaseException:  # (a signal inside: __exit__ will not run)
            self.abort()
            raise
        return self

    def __exit__(self, kind: type[BaseException] | None, exc: BaseException | None,
                 tb: TracebackType | None) -> None:
        if kind is None:
            self.close()
        else:
            self.abort()


def sequence_stream(seq: MotSequence, min_score: float = -np.inf, use_length: bool = True,
                    det_format: str = "auto") -> DetectionStream:
    """The checked :class:`DetectionStream` of a sequence (its ``seqLength`` unless not ``use_length``); ``det_format``:
    the layout (:func:`~lookalike.io.det_format.sniff_det`; other layouts read whole; assumptions in ``notes``)."""
    if seq.det_path is None:
        raise ValueError(f"{seq.name}: no detection file")
    length = seq.length if use_length else None
    where = f"seqLength in {seq.root / 'seqinfo.ini'}" if seq.root is not None else "the length"
    fmt, notes = sniff_det(seq.det_path, det_format)
    if fmt.standard():
        stream = DetectionStream(seq.det_path, length, seq.frame_rate, min_score, length_name=where,
                                 image_size=seq.image_size).check()
    else:
        table = read_det(seq.det_path, fmt, length, where)
        stream = DetectionStream.from_table(table, length, seq.frame_rate, min_score, seq.image_size)
    stream.notes = [f"{seq.det_path}: {note}" for note in notes]
    return stream


def track_to_file(tracker: Updating, frames: Iterable[Frame], output: str | os.PathLike[str],
                  sink: Sink | None = None, stats: RunStats | None = None) -> RunStats:
    """Run ``tracker`` over ``frames``, streaming its rows to ``output`` atomically; ``sink`` also sees every frame."""
    with MotWriter(output) as writer:
        return run(tracker, frames, Sinks(writer, sink), stats=stats)


__all__ = ["CHUNK_LINES", "WRITE_ROWS", "DetectionStream", "MotWriter", "sequence_stream", "track_to_file"]
