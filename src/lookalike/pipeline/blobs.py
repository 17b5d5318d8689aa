"""Blob detections for a tracker (``lookalike track --video V --detector blob``): whether they are found in the
tracking pass, and the tracker set for them."""

from __future__ import annotations

from collections.abc import Collection
from pathlib import Path
from typing import Any

import numpy as np

from lookalike.io.needs import input_kind
from lookalike.vision.blob_auto import BlobEstimate
from lookalike.vision.blob_boxtrack import blob_boxtrack_config
from lookalike.viz.blob_video import BlobRows, BlobStream, load_blob_detections


def one_pass(tracker: Any, tracker_name: str, explicit: Collection[str], n_targets: int | None,
             annotate: bool) -> bool:
    """Whether blobs are best detected in the tracking pass: the tracker's settings need no blob counts of the whole
    video, and the tracking decodes the frames anyway (``annotate``, or a tracker reading appearance features)."""
    counts = tracker_name == "boxtrack" and tracker.config.max_targets is None and "max_targets" not in explicit \
        and n_targets is None
    return (annotate or input_kind(tracker_name) != "boxes") and not counts


def blob_tracker(tracker: Any, tracker_name: str, counts: np.ndarray, explicit: Collection[str],
                 n_targets: int | None, team_size: int | None = None) -> tuple[Any, str | None, int | None]:
    """``tracker`` set for blob detections (``boxtrack`` only; ``counts``: blobs per frame, for a count inferred), the
    summary of a count inferred (None if none) and the health checks' team size: ``team_size`` when given, else the
    number of targets when known."""
    if tracker_name != "boxtrack":
        return tracker, None, team_size
    plan = blob_boxtrack_config(tracker.config, counts, explicit, n_targets)
    summary = plan.count.summary if plan.count is not None else None
    team_size = team_size if team_size is not None else plan.n_targets or None
    return (type(tracker)(plan.config) if plan.config != tracker.config else tracker), summary, team_size


def blob_source(video: Path, config: Any, tracker: Any, tracker_name: str, explicit: Collection[str],
                n_targets: int | None, offline: bool,
                options: dict[str, Any]) -> tuple[BlobRows | None, BlobStream | None]:
    """The blob detections of ``video`` stored for ``config``, else a stream that finds them in the tracking pass
    when :func:`one_pass` says so (never ``offline``), else neither (they are found first); ``options``: the
    ``min_score`` and ``annotate`` the video is tracked with."""
    found = load_blob_detections(video, config)
    if found is None and not offline and one_pass(tracker, tracker_name, explicit, n_targets,
                                                  options.get("annotate") is not None):
        return None, BlobStream(video, config, options["min_score"])
    return found, None


def estimate_lines(estimate: BlobEstimate, settings: list[str]) -> list[str]:
    """The lines telling the blob settings estimated from the video and those given with ``--blob``."""
    given = {s.partition("=")[0].strip() for s in settings}
    lines = ["blob settings estimated from the video (override with --blob KEY=VALUE):"]
    lines += [f"  {line}" for line in estimate.summary.splitlines()]
    return lines + ([f"  given with --blob: {', '.join(sorted(given))}"] if given else [])


__all__ = ["blob_source", "blob_tracker", "estimate_lines", "one_pass"]
