"""What ``boxtrack`` gets on blob detections, the one rule ``lookalike track --detector blob`` and the benches share
(docs/blobs.md): each parameter of :data:`~lookalike.vision.blob_auto.BOX_TRACKER_PARAMS` unless the user gave it (by
key, not by value), and without a known number of targets a closed set of the count inferred from the blobs
(:func:`~lookalike.vision.blob_auto.infer_target_count`; ``n_targets=0`` keeps the open set)."""

from __future__ import annotations

from collections.abc import Collection
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from lookalike.trackers.boxtrack_config import BoxTrackConfig
from lookalike.vision.blob_auto import BOX_TRACKER_PARAMS, TargetCount, infer_target_count

__all__ = ["BlobBoxTrack", "blob_boxtrack_config"]


@dataclass(frozen=True)
class BlobBoxTrack:
    """The ``boxtrack`` configuration to run on one video's blob detections.

    Attributes:
        config: the configuration to run.
        count: the number of targets inferred from the blob counts (None when it was given or not asked).
        n_targets: the closed set's size (``config.max_targets``), or None for an open set."""

    config: BoxTrackConfig
    count: TargetCount | None
    n_targets: int | None


def blob_boxtrack_config(config: BoxTrackConfig, counts: np.ndarray, explicit: Collection[str] = (),
                         n_targets: int | None = None) -> BlobBoxTrack:
    """``config`` for blob detections (module doc). ``counts``: blobs per frame ``(n_frames,)`` (frames without a blob
    as 0, :func:`~lookalike.vision.blob_auto.frame_counts`); ``explicit``: the parameter names the user gave (their
    values are kept); ``n_targets``: the known number of targets (None: infer it from ``counts``; 0: an open set)."""
    given = set(explicit)
    changes: dict[str, Any] = {k: v for k, v in BOX_TRACKER_PARAMS.items() if k not in given}
    count = None
    if config.max_targets is None and "max_targets" not in given:
        if n_targets is None:
            count = infer_target_count(counts)
            n_targets = count.n if count.closed else None
        if n_targets:
            changes["max_targets"] = int(n_targets)
    out = replace(config, **changes) if changes else config
    return BlobBoxTrack(out, count, out.max_targets)
