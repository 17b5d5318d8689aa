"""Blob detections for a tracker (``lookalike track --video V --detector blob``): the settings estimated from the
video, the detections found in the tracking pass or first (cached), the tracker set for them, and the run."""

from __future__ import annotations

from collections.abc import Callable, Collection
from contextlib import nullcontext as _nothing
from pathlib import Path
from typing import Any

import numpy as np

from lookalike.io import MotTable, write_mot
from lookalike.io.needs import input_kind
from lookalike.io.video_frames import source_frames
from lookalike.pipeline.blob_detections import (
    BlobRows,
    BlobStream,
    auto_blob_config,
    cached_blob_detections,
    load_blob_detections,
    store_blob_detections,
)
from lookalike.pipeline.runner import Event, RunResult, step
from lookalike.trackers.offline.online_look import LookIdentities, ShapeLookup, shape_lookup
from lookalike.vision.blob_auto import BOX_TRACKER_PARAMS, BlobEstimate, frame_counts
from lookalike.vision.blob_boxtrack import blob_boxtrack_config


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
    """The blob detections of ``video`` stored for ``config`` (with the large blobs' parts when ``offline``, the only
    reader of parts), else a stream that finds them in the tracking pass when :func:`one_pass` says so (never
    ``offline``), else neither (they are found first); ``options``: the ``min_score`` and ``annotate`` the video is
    tracked with."""
    found = load_blob_detections(video, config, split=offline)
    if found is None and not offline and one_pass(tracker, tracker_name, explicit, n_targets,
                                                  options.get("annotate") is not None):
        return None, BlobStream(video, config, options["min_score"], split=False)
    return found, None


def estimate_lines(estimate: BlobEstimate, settings: list[str]) -> list[str]:
    """The lines telling the blob settings estimated from the video and those given with ``--blob``."""
    given = {s.partition("=")[0].strip() for s in settings}
    lines = ["blob settings estimated from the video (override with --blob KEY=VALUE):"]
    lines += [f"  {line}" for line in estimate.summary.splitlines()]
    return lines + ([f"  given with --blob: {', '.join(sorted(given))}"] if given else [])


def run_blobs(video: Path, output: Path, tracker: Any, tracker_name: str, settings: list[str],
              on_event: Callable[[Event], None], *, n_targets: int | None = None,
              offline: dict[str, Any] | None = None, explicit: Collection[str] = (),
              save_detections: Path | None = None, **options: Any) -> RunResult:
    """Detect blobs on ``video`` (``settings``: ``--blob KEY=VALUE`` over those estimated; the boxes written to
    ``save_detections`` when given), then track them as :func:`lookalike.pipeline.video.run_video` (given
    ``options``) or, with ``offline`` (the online pass's parameters), by the offline closed set of ``n_targets``
    (None: inferred from the blob counts for ``boxtrack``; 0: an open set); ``explicit``: the tracker parameters
    given, kept as given. What it does is told to ``on_event``; ``ValueError`` for a bad input."""
    from lookalike.pipeline.closed import offline_video
    from lookalike.pipeline.video import check_result_file, run_video

    check_result_file(output, video)
    try:
        config, estimate = auto_blob_config(video, settings, n_targets or None, progress=steps(on_event))
        for line in estimate_lines(estimate, settings) if estimate is not None else []:
            on_event(Event("line", line))
        _, declared, source_rate = source_frames(video)
        found, stream = blob_source(video, config, tracker, tracker_name, explicit, n_targets, offline is not None,
                                    options)
        if found is None and stream is None:
            with step(on_event, f"detecting blobs in {video.name}") if declared <= 0 else _nothing():
                found = cached_blob_detections(video, config, None if declared <= 0 else steps(on_event)(
                    f"detecting blobs in {video.name}", declared), split=offline is not None)
    except OSError as exc:
        raise ValueError(str(exc)) from exc
    result = RunResult("blobs", [output], 1)
    rate = float(options.get("fps") or source_rate)
    if stream is not None:  # detected while tracked: the video is decoded once
        tracker = _set_tracker(tracker, tracker_name, np.zeros(0, int), explicit, n_targets, options, on_event)
        tracker = with_look(tracker, tracker_name, rate, stream.shapes_at)
        result = _with_margins(run_video(video, stream, output, tracker, tracker_name, on_event, score_warnings=False,
                                         **options), tracker, output)
        found = stream.found()
        store_blob_detections(video, config, found)
    assert found is not None
    rows, frames = found.rows, found.frames
    saved = "" if save_detections is None else f" → {write_mot(save_detections, rows)}"
    on_event(Event("line", f"blob detector: {len(rows)} boxes in {frames} frames{saved}"))
    if len(rows) < 2:
        raise ValueError(f"{video}: the blob detector found {len(rows)} box(es); try a lower --blob threshold=... "
                         "or min_area_px=..., or polarity=dark/bright")
    if stream is not None:
        return result
    if offline is not None:
        assert n_targets
        offline = {**{k: v for k, v in BOX_TRACKER_PARAMS.items() if tracker_name == "boxtrack"}, **offline}
        look = offline_video(rows, output, n_targets, offline, rate, frames,
                             options["min_score"], on_event, video=video, annotate=options.get("annotate"),
                             annotate_as=options.get("annotate_as"), shapes=found.shapes, parts=found.parts)
        if look is not None:
            result.looks[output] = look
        return result
    tracker = _set_tracker(tracker, tracker_name, frame_counts(rows, frames), explicit, n_targets, options, on_event)
    tracker = with_look(tracker, tracker_name, rate, shape_lookup(found.rows, found.shapes, frames))
    return _with_margins(run_video(video, MotTable.from_rows(rows), output, tracker, tracker_name, on_event,
                                   length=frames, score_warnings=False, **options), tracker, output)


def with_look(tracker: Any, tracker_name: str, frame_rate: float, shapes: ShapeLookup) -> Any:
    """``tracker`` with its slots' identities re-assigned by the blobs' look (:class:`LookIdentities`) when it is an
    online closed set (``boxtrack`` with ``max_targets``); ``shapes`` finds each detection's shape vector."""
    n = tracker.config.max_targets if tracker_name == "boxtrack" else None
    return LookIdentities(tracker, n, frame_rate, shapes, keep_margins=True) if n else tracker


def _with_margins(result: RunResult, tracker: Any, output: Path) -> RunResult:
    """``result`` with the look margins of ``tracker``'s rows (for their confidence) when it learned a look."""
    if isinstance(tracker, LookIdentities):
        result.looks[output] = tracker.margin_rows()
    return result


def steps(on_event: Callable[[Event], None]) -> Callable[[str, int], Callable[[], None]]:
    """A progress factory (``(description, total) -> step``) telling ``on_event`` each step and its end."""
    def factory(description: str, total: int) -> Callable[[], None]:
        on_event(Event("start", description, total))
        done = [0]

        def advance() -> None:
            done[0] += 1
            on_event(Event("advance", description, 1))
            if done[0] == total:
                on_event(Event("end", description))
        return advance
    return factory


def _set_tracker(tracker: Any, tracker_name: str, counts: np.ndarray, explicit: Collection[str],
                 n_targets: int | None, options: dict[str, Any], on_event: Callable[[Event], None]) -> Any:
    """:func:`blob_tracker`, a count inferred told; the team size set in ``options``."""
    tracker, summary, options["team_size"] = blob_tracker(tracker, tracker_name, counts, explicit, n_targets,
                                                          options.get("team_size"))
    if summary is not None:
        on_event(Event("line", summary))
    return tracker


__all__ = ["blob_source", "blob_tracker", "estimate_lines", "one_pass", "run_blobs", "steps", "with_look"]
