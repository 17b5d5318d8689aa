"""MOTChallenge rows in memory: the :class:`MotTable` of columns, one frame's tracks as rows, and a row's text. A row is
``frame, id, left, top, width, height, conf, x, y, z`` (1-based, pixels); results write ``conf`` = the identity
confidence (1 without one) and ``x, y, z`` = -1."""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from lookalike.types.tracks import Tracks, TrackSnapshot

ROW_WIDTH = 10


@dataclass(frozen=True, eq=False)
class MotTable:
    """A MOTChallenge file as columns (one row per box).

    Attributes:
        frame: ``(n,)`` 1-based frame numbers.
        track_id: ``(n,)`` ids (-1 in detection files).
        xywh: ``(n, 4)`` boxes in pixels.
        conf: ``(n,)`` detector score, or the ground truth's consider flag.
        extra: ``(n, k)`` the remaining columns (world xyz, or class and visibility in MOT16+ gt).
        path: the file it came from, if any."""

    frame: np.ndarray
    track_id: np.ndarray
    xywh: np.ndarray
    conf: np.ndarray
    extra: np.ndarray
    path: Path | None = None

    def __len__(self) -> int:
        return int(self.frame.shape[0])

    @classmethod
    def from_rows(cls, rows: np.ndarray) -> MotTable:
        """A table from in-memory MOTChallenge rows ``(n, >= 7)`` such as :func:`tracks_to_rows` makes."""
        data = np.asarray(rows, dtype=float).reshape(-1, max(np.shape(rows)[-1], 7) if np.size(rows) else 10)
        return table_from_array(data, None)


def table_from_array(data: np.ndarray, path: Path | None = None) -> MotTable:
    """A :class:`MotTable` from parsed rows ``(n, >= 6)`` (conf 1 when there is no 7th column)."""
    n = data.shape[0]
    conf = data[:, 6] if data.shape[1] > 6 else np.ones(n)
    extra = data[:, 7:] if data.shape[1] > 7 else np.zeros((n, 0))
    return MotTable(frame=data[:, 0].astype(int), track_id=data[:, 1].astype(int), xywh=data[:, 2:6].copy(),
                    conf=conf.copy(), extra=extra.copy(), path=path)


def tracks_to_rows(frame_index: int, tracks: Iterable[TrackSnapshot]) -> np.ndarray:
    """MOTChallenge result rows ``(k, 10)`` for the boxed tracks of one 0-based frame index."""
    if isinstance(tracks, Tracks):  # columnar batch: no per-track objects
        return tracks.to_rows(frame_index)
    boxed = [t for t in tracks if t.xywh is not None]
    rows = np.full((len(boxed), ROW_WIDTH), -1.0)
    for r, t in enumerate(boxed):
        rows[r, 0] = frame_index + 1
        rows[r, 1] = t.track_id
        rows[r, 2:6] = t.xywh
        rows[r, 6] = 1.0 if t.identity_prob is None else t.identity_prob
    return rows


def detection_rows(frame: int | np.ndarray, xywh: np.ndarray, score: np.ndarray | float) -> np.ndarray:
    """MOTChallenge detection rows ``(k, 10)``: 1-based ``frame``, -1, ``xywh (k, 4)`` (px), ``score``, -1, -1, -1."""
    xywh = np.asarray(xywh, dtype=float).reshape(-1, 4)
    rows = np.full((len(xywh), ROW_WIDTH), -1.0)
    rows[:, 0], rows[:, 2:6], rows[:, 6] = frame, xywh, score
    return rows


def stack_rows(chunks: Iterable[np.ndarray]) -> np.ndarray:
    """Row blocks ``(k_i, 10)`` stacked into ``(sum k_i, 10)`` (``(0, 10)`` when there are none); ``ValueError``
    naming a block of another shape."""
    parts = [np.asarray(c, dtype=float) for c in chunks]
    for i, p in enumerate(parts):
        if p.size and (p.ndim != 2 or p.shape[1] != ROW_WIDTH):
            raise ValueError(f"rows[{i}]: result rows need shape (k, {ROW_WIDTH}), got {p.shape}")
    parts = [p.reshape(-1, ROW_WIDTH) for p in parts]
    return np.vstack(parts) if parts else np.zeros((0, ROW_WIDTH))


__all__ = ["ROW_WIDTH", "MotTable", "detection_rows", "stack_rows", "table_from_array", "tracks_to_rows"]
