"""The ``--targets N --offline`` and ``--points FILE`` branches of ``lookalike track``: the offline closed set
(:func:`lookalike.trackers.offline.closed_set.track_closed_set`) and anonymous points tracked as small boxes."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
from rich.markup import escape

from lookalike.cli.app import console, fail, failing
from lookalike.cli.track import input_error, sequences_and_targets
from lookalike.io import frames_from_table, read_mot, write_mot
from lookalike.io.det_format import read_det, sniff_det
from lookalike.io.outputs import ensure_writable
from lookalike.io.points import POINT_VEL_NOISE, points_to_rows, read_points_csv, read_points_mot, typical_spacing
from lookalike.io.stream import track_to_file
from lookalike.trackers.boxtrack import BoxTrack
from lookalike.trackers.offline.closed_set import online_rows, track_closed_set
from lookalike.types.mot_table import MotTable, detection_rows

POINTS_FPS = 25.0  # frame rate assumed for point files when --fps is not given (frames/s)
MAX_POINTS_PER_FRAME = 100_000
"""Points in one frame that ``track --points`` accepts (memory grows linearly with them: about 260 MB at 10,000 a
frame; benchmarks/points_memory.py)."""


def check_result_file(output: Path, video: Path | None = None) -> None:
    """Fail unless ``output`` can be the ``--video`` branch's result file and ``video`` (if given) exists."""
    if output.is_dir():
        fail(f"-o/--output: {output} is a folder; with --video give a result file such as tracks.txt")
    if video is not None and not video.exists():
        fail(f"--video: {video} does not exist")


def table_rows(path: Path, min_score: float = float("-inf"), length: int | None = None,
               length_name: str = "the length", det_format: str = "auto") -> np.ndarray:
    """Detection rows ``(k, 10)`` of a detection file, those scoring below ``min_score`` dropped (``length``: frames
    past it are an error; ``det_format``: its layout, what was assumed printed as a note)."""
    fmt, notes = sniff_det(path, det_format)
    for line in notes:
        console.print(f"[cyan]note:[/] {escape(f'{path}: {line}')}", highlight=False)
    table = read_mot(path, length=length, length_name=length_name) if fmt.standard() else \
        read_det(path, fmt, length, length_name)
    rows = detection_rows(table.frame, table.xywh, table.conf)
    return rows[rows[:, 6] >= min_score]


def closed_set_rows(det_rows: np.ndarray, n_targets: int, frame_rate: float, n_frames: int | None,
                    params: dict[str, Any], vel_noise: float | None = None,
                    shapes: np.ndarray | None = None) -> np.ndarray:
    """Offline closed-set result rows (ids ``1..n_targets``) of detection rows; ``params``: the online ``boxtrack``
    pass's parameters (``max_targets`` dropped); ``vel_noise``: its velocity noise when not boxtrack's own;
    ``shapes``: each detection's blob shape vector (the look learned from them weighs in). Too few detections for
    the offline assignment get the online closed set's result instead, with a printed note."""
    online = {k: v for k, v in params.items() if k != "max_targets"}
    rows = track_closed_set(det_rows, n_targets, frame_rate, n_frames=n_frames, online=online, vel_noise=vel_noise,
                            shapes=shapes)
    if len(rows) or not len(det_rows):
        return rows
    frames = len(np.unique(det_rows[:, 0]))
    console.print(f"note: {frames} frame(s) of detections are too few for the offline closed set; the online closed "
                  f"set's result (boxtrack --targets {n_targets}) is written instead", markup=False)
    return online_rows(det_rows, frame_rate, n_frames, vel_noise=vel_noise, **{**online, "max_targets": n_targets})


def point_tracker(tracker: Any) -> Any:
    """``tracker`` for points as boxes: a ``boxtrack`` rebuilt with the points' velocity noise; others unchanged."""
    return BoxTrack(tracker.config, vel_noise=POINT_VEL_NOISE) if isinstance(tracker, BoxTrack) else tracker


def offline_files(path: Path, output: Path, n_targets: int, params: dict[str, Any], min_score: float,
                  use_length: bool = True, det_format: str = "auto") -> int:
    """``--offline`` over every sequence at ``path`` (outputs decided first; ``use_length``: seqinfo.ini's seqLength
    bounds the frames): returns the sequences written."""
    try:
        sequences, targets = sequences_and_targets(path, output)
        ensure_writable(targets)
        for seq, target in zip(sequences, targets):
            assert seq.det_path is not None
            length = seq.length if use_length else None
            det = table_rows(seq.det_path, min_score, length, f"seqLength in {seq.root / 'seqinfo.ini'}"
                             if seq.root is not None else "the length", det_format)
            n_frames = max((seq.length if use_length else None) or 0, int(det[:, 0].max(initial=0)))
            with console.status(f"closed set of {n_targets} on {seq.name}"):
                rows = closed_set_rows(det, n_targets, seq.frame_rate, n_frames, params)
            write_mot(target, rows)
    except (FileNotFoundError, ValueError) as exc:
        fail(input_error(exc))
    except OSError as exc:
        fail(f"output {output}: cannot write ({exc.strerror or exc})")
    return len(sequences)


def offline_video(det: Path | np.ndarray, output: Path, n_targets: int, params: dict[str, Any], frame_rate: float,
                  n_frames: int | None, min_score: float, det_format: str = "auto", *, video: Path | None = None,
                  annotate: Path | None = None, annotate_as: Path | None = None,
                  shapes: np.ndarray | None = None) -> None:
    """``--video ... --offline``: the closed set over the detections ``det`` (a file, or rows a detector found, with
    ``shapes``: each row's blob shape vector), written to ``output``; with ``annotate``, its identities drawn on
    ``video`` into that MP4 (printed as ``annotate_as``)."""
    with failing(FileNotFoundError, ValueError):
        rows = table_rows(det, min_score, det_format=det_format) if isinstance(det, Path) else \
            det[det[:, 6] >= min_score]
        shapes = shapes if shapes is not None and len(shapes) == len(rows) else None
        with console.status(f"closed set of {n_targets}" + (", learning each one's look" if shapes is not None
                                                             else "")):
            rows = closed_set_rows(rows, n_targets, frame_rate, n_frames, params, shapes=shapes)
    write_mot(output, rows)
    console.print(f"[green]boxtrack[/], offline closed set of {n_targets}: {len(np.unique(rows[:, 1]))} "
                  f"identities, {len(rows)} rows at {frame_rate:g} frames/s → {output}")
    if annotate is not None and video is not None:
        from lookalike.io import MotTable
        from lookalike.viz.overlay import overlay_tracks

        with failing(ValueError, OSError), console.status("drawing the identities"):
            overlay_tracks(video, MotTable.from_rows(rows), annotate, fps=frame_rate)
        console.print(f"annotated video → {escape(str(annotate_as or annotate))}")


def read_points(path: Path) -> Any:
    """Points of a ``frame,x,y`` CSV (``.csv``) or of MOTChallenge rows with a point per row (any other suffix)."""
    return read_points_csv(path) if path.suffix.lower() == ".csv" else read_points_mot(path)


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
        points = read_points(points_path)
        counts = [len(p) for p in points.points]
        if counts and max(counts) > MAX_POINTS_PER_FRAME:
            frame = int(np.argmax(counts)) + 1
            raise ValueError(f"{points_path}: frame {frame} has {max(counts)} points; at most {MAX_POINTS_PER_FRAME} "
                             "a frame are tracked")
        spacing = typical_spacing(points)
        det = points_to_rows(points)
    side = float(det[0, 4]) if len(det) else 1.0
    why = f"half the typical spacing {spacing:.3g}" if spacing > 0 else "one point a frame: twice the typical step"
    console.print(f"points: {points.count} in {len(points)} frames, boxes of {side:.3g} ({why}), "
                  f"{frame_rate:g} frames/s" + ("" if fps else " (--fps to change)"))
    if offline:
        assert n_targets is not None
        with failing(ValueError):
            rows = closed_set_rows(det, n_targets, frame_rate, len(points), params, vel_noise=POINT_VEL_NOISE)
        write_mot(output, rows)
    else:
        with failing(ValueError):
            track_to_file(point_tracker(tracker), frames_from_table(MotTable.from_rows(det), len(points), frame_rate),
                          output)
        table = read_mot(output)
        rows = np.column_stack([table.frame, table.track_id]) if len(table) else np.zeros((0, 2))
    what = f"offline closed set of {n_targets}" if offline else "online"
    console.print(f"[green]{tracker_name}[/], {what}: {len(np.unique(rows[:, 1]))} identities → {escape(str(output))}")
    if annotate is not None:
        from lookalike.viz.overlay import blank_frames, overlay_tracks

        tracks = read_mot(output)
        with failing(ValueError, OSError), console.status("drawing the tracks"):
            overlay_tracks(video if video is not None else blank_frames(tracks, len(points)), tracks, annotate,
                           fps=frame_rate)
        console.print(f"annotated video → {escape(str(annotate_as or annotate))}")


__all__ = ["MAX_POINTS_PER_FRAME", "POINTS_FPS", "closed_set_rows", "offline_files", "offline_video", "point_tracker",
           "read_points", "table_rows", "track_points"]
