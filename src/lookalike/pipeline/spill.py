"""Frames' detections and their appearance features kept on disk rather than in memory (:class:`FrameSpill`), for a
pass that needs the whole video before it can use them."""

from __future__ import annotations

import dataclasses
import tempfile
from collections.abc import Iterator
from typing import Any

import numpy as np

from lookalike.types import Detections

_COLUMNS = tuple(f.name for f in dataclasses.fields(Detections) if f.name != "feature")


class FrameSpill:
    """Each frame's :class:`~lookalike.types.Detections` (every column: boxes, scores, ...) and ``(n, d)`` features
    appended to an anonymous temporary file (in ``TMPDIR``; no name on Linux, removed once closed or the process
    ends), then read back in order as often as needed: memory O(one frame) whatever the video's length. Arrays
    are written as ``.npy`` records, so they read back bit for bit (float64 stays float64). Append every frame
    before reading; close (or use as a context manager) when done."""

    def __init__(self) -> None:
        self._file = tempfile.TemporaryFile(prefix="lookalike-", suffix=".frames")
        self.frames = 0  # frames appended
        self.boxes = 0  # detections appended, all frames

    def append(self, det: Detections, feature: np.ndarray) -> None:
        """Add the next frame: ``det`` (its ``feature`` column left out) and its ``feature`` ``(len(det), d)``."""
        columns = [getattr(det, name) for name in _COLUMNS]
        np.save(self._file, np.array([c is not None for c in columns]), allow_pickle=False)
        for column in columns:
            if column is not None:
                np.save(self._file, column, allow_pickle=False)
        np.save(self._file, feature, allow_pickle=False)
        self.frames += 1
        self.boxes += len(det)

    def read(self) -> Iterator[Detections]:
        """The frames appended, in order, each with its features as ``feature``; one reading at a time."""
        self._file.flush()
        self._file.seek(0)
        for _ in range(self.frames):
            present = np.load(self._file, allow_pickle=False)
            columns: dict[str, Any] = {name: np.load(self._file, allow_pickle=False) if here else None
                                       for name, here in zip(_COLUMNS, present)}
            yield Detections(**columns, feature=np.load(self._file, allow_pickle=False))

    @property
    def closed(self) -> bool:
        """Whether the file is closed (and gone)."""
        return bool(self._file.closed)

    def close(self) -> None:
        """Close the file, which removes it."""
        self._file.close()

    def __enter__(self) -> FrameSpill:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


__all__ = ["FrameSpill"]
