"""The ``--video FILE --detector blob`` branch of ``lookalike track``: blob settings estimated from the video (``--blob
KEY=VALUE`` overrides them), detections cached (written out with ``--save-detections``) and tracked (docs/blobs.md)."""

from __future__ import annotations

from collections.abc import Collection
from pathlib import Path
from typing import Any

import numpy as np

from lookalike.cli.app import console, fail, failing
from lookalike.cli.progress import progress_bars
from lookalike.cli.track_closed import check_result_file, offline_video
from lookalike.cli.track_video import run_track_onnx, run_track_video, save_detections
from lookalike.io import MotTable
from lookalike.pipeline.blobs import blob_source, blob_tracker, estimate_lines
from lookalike.vision.blob_auto import BOX_TRACKER_PARAMS, frame_counts
from lookalike.viz.blob_video import (
    BlobRows,
    auto_blob_config,
    cached_blob_detections,
    store_blob_detections,
)
from lookalike.viz.overlay import source_frames

DETECTORS = ("blob",)


def _detect_with_progress(video: Path, config: Any, declared: int) -> BlobRows:
    """:func:`~lookalike.viz.blob_video.cached_blob_detections` with a bar of ``declared`` frames on a terminal,
    or a spinner when the video does not declare its frame count."""
    if declared <= 0:
        with console.status(f"detecting blobs in {video.name}"):
            return cached_blob_detections(video, config)
    with progress_bars() as progress:
        return cached_blob_detections(video, config, progress(f"detecting blobs in {video.name}", declared))


def run_track_blobs(video: Path, output: Path, tracker: Any, tracker_name: str, detector: str,
                    settings: list[str], *, n_targets: int | None = None, offline: dict[str, Any] | None = None,
                    explicit: Collection[str] = (), **options: Any) -> None:
    """Detect blobs on ``video`` (saved to ``options["save_detections"]`` when given), then track them as
    :func:`~lookalike.cli.track_video.run_track_video` (given ``options``) or, with ``offline`` (the online pass's
    parameters), by the offline closed set of ``n_targets`` (None: inferred from the blob counts for ``boxtrack``;
    0: an open set). ``explicit``: the tracker parameters the user gave, kept as given."""
    if detector.lower().endswith(".onnx"):
        return run_track_onnx(video, output, tracker, tracker_name, Path(detector), settings, n_targets=n_targets,
                              offline=offline, **options)
    if detector not in DETECTORS:
        fail(f"--detector: choose one of {', '.join(DETECTORS)} or FILE.onnx, got {detector!r}")
    check_result_file(output, video)
    with failing(ValueError, OSError):
        with progress_bars() as progress:  # (steps: reading the sampled frames, the background, each threshold)
            config, estimate = auto_blob_config(video, settings, n_targets or None, progress=progress)
        for line in estimate_lines(estimate, settings) if estimate is not None else []:
            console.print(line, markup=False)
        _, declared, source_rate = source_frames(video)
        frame_rate = options.get("fps") or source_rate
        found, stream = blob_source(video, config, tracker, tracker_name, explicit, n_targets, offline is not None,
                                    options)
        if found is None and stream is None:
            found = _detect_with_progress(video, config, declared)
    saved = options.pop("save_detections", None)
    if stream is not None:  # detected while tracked: the video is decoded once
        tracker = _blob_tracker(tracker, tracker_name, np.zeros(0, int), explicit, n_targets, options)
        run_track_video(video, stream, output, tracker, tracker_name, score_warnings=False, **options)
        found = stream.found()
        store_blob_detections(video, config, found)
    assert found is not None
    rows, frames = found.rows, found.frames
    console.print(f"blob detector: {len(rows)} boxes in {frames} frames"
                  + save_detections(rows, {"save_detections": saved}), markup=False)
    if len(rows) < 2:
        fail(f"{video}: the blob detector found {len(rows)} box(es); try a lower --blob threshold=... "
             "or min_area_px=..., or polarity=dark/bright")
    if stream is not None:
        return
    if offline is not None:
        assert n_targets
        offline = {**{k: v for k, v in BOX_TRACKER_PARAMS.items() if tracker_name == "boxtrack"}, **offline}
        offline_video(rows, output, n_targets, offline, float(frame_rate), frames, options["min_score"],
                      video=video, annotate=options.get("annotate"), annotate_as=options.get("annotate_as"),
                      shapes=found.shapes)
        return
    tracker = _blob_tracker(tracker, tracker_name, frame_counts(rows, frames), explicit, n_targets, options)
    run_track_video(video, MotTable.from_rows(rows), output, tracker, tracker_name, length=frames,
                    score_warnings=False, **options)


def _blob_tracker(tracker: Any, tracker_name: str, counts: np.ndarray, explicit: Collection[str],
                  n_targets: int | None, options: dict[str, Any]) -> Any:
    """:func:`lookalike.pipeline.blobs.blob_tracker`, a count inferred printed; the team size set in ``options``."""
    tracker, summary, options["team_size"] = blob_tracker(tracker, tracker_name, counts, explicit, n_targets,
                                                          options.get("team_size"))
    if summary is not None:
        console.print(summary, markup=False)
    return tracker
