"""``lookalike track --video FILE --detector blob``: detections from the blob detector instead of a det.txt.

The video is read twice: once to fit the median background on ``history`` frames spread evenly over
it (the ``median`` method; ``mog2`` learns online and skips this pass), once to detect. The blob
boxes are written as a MOTChallenge detection file ``<output stem>.det.txt`` beside the result, and
that file feeds the ordinary ``--video`` branch (:func:`~lookalike.cli.track_video.run_track_video`):
any registered tracker, health monitor, optional annotated video. Not a command of its own.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from lookalike.cli.app import console, fail
from lookalike.cli.track_video import run_track_video
from lookalike.io import write_mot
from lookalike.viz.blob_video import blob_config, blob_detection_rows

DETECTORS = ("blob",)


def run_track_blobs(video: Path, output: Path, tracker: Any, tracker_name: str, detector: str,
                    settings: list[str], **options: Any) -> None:
    """Detect blobs on ``video``, write them to ``<output stem>.det.txt``, then track them as
    :func:`~lookalike.cli.track_video.run_track_video` does (``options`` are passed on to it)."""
    if detector not in DETECTORS:
        fail(f"--detector: choose one of {', '.join(DETECTORS)}, got {detector!r}")
    if output.is_dir():
        fail(f"-o/--output: {output} is a folder; with --video give a result file such as tracks.txt")
    if not video.exists():
        fail(f"--video: {video} does not exist")
    try:
        config = blob_config(settings)
        with console.status(f"detecting blobs in {video.name}"):
            rows, frames = blob_detection_rows(video, config)
    except (ValueError, OSError) as exc:
        fail(str(exc))
    det_path = write_mot(output.with_name(output.stem + ".det.txt"), rows)
    console.print(f"blob detector: {len(rows)} boxes in {frames} frames → {det_path}")
    if len(rows) < 2:
        fail(f"{video}: the blob detector found {len(rows)} box(es); try a lower --blob threshold=... "
             "or min_area_px=..., or polarity=dark/bright")
    run_track_video(video, det_path, output, tracker, tracker_name, **options)
