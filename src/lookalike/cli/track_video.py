"""The ``--video`` branch of ``lookalike track``, printed: the run is :func:`lookalike.pipeline.video.run_video`
(features from the frames' pixels, tracks, merges, detector health, optional annotated video)."""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

import numpy as np
from rich.markup import escape

from lookalike.cli.app import console, fail, failing
from lookalike.cli.progress import bars, printed_events
from lookalike.cli.track_closed import check_result_file, offline_video
from lookalike.io import MotTable, write_mot
from lookalike.pipeline.video import VideoDetections, as_written, open_onnx, run_video

__all__ = ["interrupted", "run_track_onnx", "run_track_video", "save_detections"]


def run_track_video(video: Path, detections: VideoDetections, output: Path, tracker: Any, tracker_name: str, *,
                    annotate_as: Path | None = None, **options: Any) -> None:
    """:func:`lookalike.pipeline.video.run_video` given ``options``, printed (the ``annotate`` MP4 as
    ``annotate_as``)."""
    with failing(ValueError), interrupted(options.get("annotate"), annotate_as), printed_events(tracker_name) as tell:
        run_video(video, detections, output, tracker, tracker_name, tell, annotate_as=annotate_as, **options)


@contextmanager
def interrupted(annotate: Path | None, annotate_as: Path | None = None) -> Iterator[None]:
    """Ctrl-C in the block: a line saying that nothing was written, exit 130."""
    try:
        yield
    except KeyboardInterrupt:
        console.print("\n[yellow]Interrupted.[/] Nothing was written"
                      + (f" ({escape(str(annotate_as or annotate))} is left as it was)." if annotate else "."))
        raise SystemExit(130) from None


def run_track_onnx(video: Path, output: Path, tracker: Any, tracker_name: str, model: Path, settings: list[str], *,
                   n_targets: int | None = None, offline: dict[str, Any] | None = None, **options: Any) -> None:
    """``track --video V --detector FILE.onnx``: detect with the ONNX model (``settings``: ``KEY=VALUE``; the boxes
    saved to ``options["save_detections"]`` when given), then track as :func:`run_track_video` (given ``options``;
    detected in the tracking pass when it decodes the frames anyway) or, with ``offline``, by the offline closed set
    of ``n_targets``."""
    check_result_file(output, video)
    with failing(ValueError, OSError):
        run = open_onnx(video, model, settings)
        stream = run.in_pass(tracker_name, options.get("annotate") is not None, offline is not None,
                             options["min_score"])
        saved = {"save_detections": options.pop("save_detections", None)}
        if stream is not None:
            run_track_video(video, stream, output, tracker, tracker_name, **options)
            rows, frames, seconds = stream.found()
        else:
            with bars("detecting {task.description}") as progress:
                task = progress.add_task(video.name, total=run.total or None)
                rows, frames, seconds = run.detect(advance=lambda: progress.advance(task))
    speed = f"{frames / seconds:,.1f} frames/s" if seconds > 0 else "inf frames/s"
    width, height = run.detector.input_size
    console.print(f"{model.name} ({run.detector.layout}, input {width}x{height}): "
                  f"{len(rows)} boxes in {frames} frames, {speed}" + save_detections(rows, saved))
    if len(rows) < 2:
        fail(f"{video}: the detector {model.name} found {len(rows)} box(es); try a lower score=... setting")
    if stream is not None:
        return
    rows = as_written(rows)  # (tracked as a saved detection file would be: boxes to 1/1000 px, scores to 6 digits)
    if offline is not None:
        assert n_targets is not None
        offline_video(rows, output, n_targets, offline, float(options.get("fps") or run.rate), frames,
                      options["min_score"])
    else:
        run_track_video(video, MotTable.from_rows(rows), output, tracker, tracker_name, length=frames, **options)


def save_detections(rows: np.ndarray, options: dict[str, Any]) -> str:
    """Write ``rows`` to ``options["save_detections"]`` (popped; ``--save-detections``) when given: `` → PATH`` for
    the printed line, else ``""``."""
    path = options.pop("save_detections", None)
    return "" if path is None else f" → {write_mot(path, rows)}"
