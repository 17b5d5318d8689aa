"""The closed set behind a blob video's tracks, so that proofreading re-solves it with the look learned from the video
(as ``track --video V --detector blob --targets N`` made it)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from lookalike.io.motchallenge import read_mot
from lookalike.pipeline.blob_detections import auto_blob_config, load_blob_detections
from lookalike.trackers.offline.closed_set import assign_identities, closed_set_input
from lookalike.vision.blob_auto import BOX_TRACKER_PARAMS

__all__ = ["blob_solver_input"]


def blob_solver_input(video: Path, tracks: Path, n_targets: int, frame_rate: float
                      ) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:
    """``(solver rows, shapes, parts)`` for :class:`lookalike.proofread.Session` when ``tracks`` are what ``track
    --video VIDEO --detector blob --targets N`` writes with its defaults from the blobs cached for ``video``: the
    offline closed set's input rows (column 9 indexing ``shapes``) and the blobs' shape and parts vectors. None when
    no blobs are cached with the settings estimated for ``n_targets``, or when the closed set solved from them does not
    give ``tracks`` (other settings, another detector, edited tracks). ``frame_rate`` in frames/s."""
    found = load_blob_detections(video, auto_blob_config(video, [], n_targets)[0])
    if found is None or found.shapes is None or len(found.rows) < 2:
        return None
    solver = closed_set_input(found.rows, frame_rate, found.frames, online=dict(BOX_TRACKER_PARAMS), index=True)
    again = assign_identities(solver, n_targets, frame_rate, shapes=found.shapes, parts=found.parts)
    table = read_mot(tracks)
    given = np.column_stack([table.frame, table.track_id, table.xywh])
    again = again[:, :6]
    if given.shape != again.shape:
        return None
    given, again = (a[np.lexsort((a[:, 1], a[:, 0]))] for a in (given, again))
    return (solver, found.shapes, found.parts) if np.allclose(given, again, atol=0.01) else None
