"""The last step of a ``lookalike track`` run: each written result file gets its rows' identity confidence
(:mod:`lookalike.trackers.offline.confidence`) in column 7, and the doubtful ranges are described."""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path

import numpy as np

from lookalike.io import find_sequences, read_mot, write_mot
from lookalike.io.outputs import result_paths
from lookalike.pipeline.closed import POINTS_FPS
from lookalike.trackers.offline.confidence import (
    assignment_confidence,
    by_frame_and_id,
    describe_ranges,
    doubtful_ranges,
)


def written_results(branch: str, path: Path | None, output: Path, video: Path | None, fps: float | None,
                    live: bool = False) -> list[tuple[Path, float]]:
    """The result files ``track`` wrote on ``branch`` (``points``, ``blobs``, ``video`` or ``files``), each with its
    frame rate (frames/s); none from a ``live`` source (its rows are written as they come)."""
    if live:
        return []
    if branch == "points":
        return [(output, fps or POINTS_FPS)]
    if branch in ("blobs", "video"):
        from lookalike.io.video_frames import source_frames

        rate = fps or (source_frames(video)[2] if video is not None else None)
        return [(output, float(rate or 25.0))]
    assert path is not None
    sequences = [s for s in find_sequences(path) if s.det_path is not None]
    return [(target, s.frame_rate) for s, target in zip(sequences, result_paths(path, sequences, output))]


def add_confidence(results: list[tuple[Path, float]], looks: Mapping[Path, np.ndarray] | None = None) -> list[str]:
    """Rewrite column 7 of each ``(result file, frames/s)`` as its rows' confidence (3 decimals), with the look
    margins of ``looks`` (per file, ``(frame, id, margin)`` rows) where a file has them; returns a line of doubtful
    ranges per file (named when there are several)."""
    lines = []
    for path, rate in results:
        table = read_mot(path) if path.is_file() and path.stat().st_size else None
        if table is None or not len(table):
            continue
        extra = np.full((len(table), 3), -1.0)
        extra[:, :min(3, table.extra.shape[1])] = table.extra[:, :3]
        rows = np.column_stack([table.frame, table.track_id, table.xywh, table.conf, extra])
        look = by_frame_and_id(rows, looks[path]) if looks and path in looks else None
        rows[:, 6] = np.round(assignment_confidence(rows, rate, look=look), 3)
        write_mot(path, rows)
        line = describe_ranges(doubtful_ranges(rows, rows[:, 6], rate))
        lines.append(f"{path.name}: {line}" if len(results) > 1 else line)
    return lines


__all__ = ["add_confidence", "written_results"]
