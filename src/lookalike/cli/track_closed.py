"""The ``--targets N --offline`` and ``--points FILE`` branches of ``lookalike track``: options and printing; the work
is :mod:`lookalike.pipeline.closed`."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
from rich.markup import escape

from lookalike.cli.app import console, fail, failing
from lookalike.io import MotTable, read_mot, write_mot
from lookalike.pipeline import closed
from lookalike.pipeline.closed import MAX_POINTS_PER_FRAME, POINTS_FPS, point_tracker, read_points
from lookalike.pipeline.files import input_error


def check_result_file(output: Path, video: Path | None = None) -> None:
    """Fail unless ``output`` can be the ``--video`` branch's result file and ``video`` (if given) exists."""
    from lookalike.pipeline.video import check_result_file as check

    with failing(ValueError):
        check(output, video)


def _note(line: str) -> None:
    console.print(line, markup=False)


def _file_note(line: str) -> None:
    console.print(f"[cyan]note:[/] {escape(line)}", highlight=False)


def offline_files(path: Path, output: Path, n_targets: int, params: dict[str, Any], min_score: float,
                  use_length: bool = True, det_format: str = "auto") -> int:
    """``--offline`` over every sequence at ``path`` (outputs decided first; ``use_length``: seqinfo.ini's seqLength
    bounds the frames): returns the sequences written."""
    try:
        return closed.offline_sequences(path, output, n_targets, params, min_score, use_length, det_format,
                                        note=_note, file_note=_file_note, status=console.status)
    except (FileNotFoundError, ValueError) as exc:
        fail(input_error(exc))
    except OSError as exc:
        fail(f"output {output}: cannot write ({exc.strerror or exc})")


def offline_video(det: Path | np.ndarray, output: Path, n_targets: int, params: dict[str, Any], frame_rate: float,
                  n_frames: int | None, min_score: float, det_format: str = "auto", *, video: Path | None = None,
                  annotate: Path | None = None, annotate_as: Path | None = None,
                  shapes: np.ndarray | None = None) -> None:
    """``--video ... --offline``: the closed set over the detections ``det`` (a file, or rows a detector found, with
    ``shapes``: each row's blob shape vector), written to ``output``; with ``annotate``, its identities drawn on
    ``video`` into that MP4 (printed as ``annotate_as``)."""
    with failing(FileNotFoundError, ValueError):
        rows = closed.offline_rows(det, n_targets, params, frame_rate, n_frames, min_score, det_format, shapes,
                                   note=_note, file_note=_file_note, status=console.status)
    write_mot(output, rows)
    console.print(f"[green]boxtrack[/], offline closed set of {n_targets}: {len(np.unique(rows[:, 1]))} "
                  f"identities, {len(rows)} rows at {frame_rate:g} frames/s → {output}")
    if annotate is not None and video is not None:
        with failing(ValueError, OSError), console.status("drawing the identities"):
            closed.draw_tracks(MotTable.from_rows(rows), annotate, frame_rate, video)
        console.print(f"annotated video → {escape(str(annotate_as or annotate))}")


def track_points(points_path: Path, output: Path, tracker: Any, tracker_name: str, *, n_targets: int | None,
                 offline: bool, params: dict[str, Any], fps: float | None, annotate: Path | None = None,
                 annotate_as: Path | None = None, video: Path | None = None) -> None:
    """``--points FILE``: points as boxes of half their typical spacing, tracked online by ``tracker`` or, with
    ``offline``, by the closed set of ``n_targets``; result rows (boxes centred on the points) to ``output``; with
    ``annotate``, the tracks drawn on ``video`` (or on white frames) into that MP4 (printed as ``annotate_as``)."""
    if output.is_dir():
        fail(f"-o/--output: {output} is a folder; with --points give a result file such as tracks.txt")
    frame_rate = fps or POINTS_FPS
    with failing(FileNotFoundError, ValueError):
        boxes = closed.point_boxes(points_path)
    why = f"half the typical spacing {boxes.spacing:.3g}" if boxes.spacing > 0 else \
        "one point a frame: twice the typical step"
    console.print(f"points: {boxes.count} in {boxes.frames} frames, boxes of {boxes.side:.3g} ({why}), "
                  f"{frame_rate:g} frames/s" + ("" if fps else " (--fps to change)"))
    with failing(ValueError):
        rows = closed.track_point_boxes(boxes, output, tracker, frame_rate, n_targets, params if offline else None,
                                        note=_note)
    what = f"offline closed set of {n_targets}" if offline else "online"
    console.print(f"[green]{tracker_name}[/], {what}: {len(np.unique(rows[:, 1]))} identities → {escape(str(output))}")
    if annotate is not None:
        tracks = read_mot(output)
        with failing(ValueError, OSError), console.status("drawing the tracks"):
            closed.draw_tracks(tracks, annotate, frame_rate, video, boxes.frames)
        console.print(f"annotated video → {escape(str(annotate_as or annotate))}")


__all__ = ["MAX_POINTS_PER_FRAME", "POINTS_FPS", "check_result_file", "offline_files", "offline_video", "point_tracker",
           "read_points", "track_points"]
