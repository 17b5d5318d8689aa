"""Detection rows for the offline closed set (:func:`lookalike.trackers.offline.closed_set.track_closed_set`) and
anonymous points tracked as small boxes (``lookalike track --offline``, ``--points``)."""

from __future__ import annotations

from collections.abc import Callable
from contextlib import AbstractContextManager, nullcontext
from dataclasses import dataclass
from functools import partial
from pathlib import Path
from typing import Any

import numpy as np

from lookalike.io import frames_from_table, read_mot, write_mot
from lookalike.io.det_format import read_det, sniff_det
from lookalike.io.outputs import ensure_writable
from lookalike.io.points import POINT_VEL_NOISE, points_to_rows, read_points_csv, read_points_mot, typical_spacing
from lookalike.io.stream import track_to_file
from lookalike.pipeline.runner import Event, step, telling
from lookalike.trackers.boxtrack import BoxTrack
from lookalike.trackers.offline.closed_set import closed_set_and_look, online_rows
from lookalike.types.mot_table import MotTable, detection_rows

Note = Callable[[str], None]  # told each note line (plain text)

POINTS_FPS = 25.0  # frame rate assumed for point files when --fps is not given (frames/s)
MAX_POINTS_PER_FRAME = 100_000
"""Points in one frame that ``track --points`` accepts (memory grows linearly with them: about 260 MB at 10,000 a
frame; benchmarks/points_memory.py)."""


def _silent(line: str) -> None:
    return None


def table_rows(path: Path, min_score: float = float("-inf"), length: int | None = None,
               length_name: str = "the length", det_format: str = "auto", note: Note = _silent) -> np.ndarray:
    """Detection rows ``(k, 10)`` of a detection file, those scoring below ``min_score`` dropped (``length``: frames
    past it are an error; ``det_format``: its layout, what was assumed told to ``note``)."""
    fmt, notes = sniff_det(path, det_format)
    for line in notes:
        note(f"{path}: {line}")
    table = read_mot(path, length=length, length_name=length_name, positive_size=True) if fmt.standard() else \
        read_det(path, fmt, length, length_name)
    rows = detection_rows(table.frame, table.xywh, table.conf)
    return rows[rows[:, 6] >= min_score]


def closed_set_rows(det_rows: np.ndarray, n_targets: int, frame_rate: float, n_frames: int | None,
                    params: dict[str, Any], vel_noise: float | None = None,
                    shapes: np.ndarray | None = None, parts: np.ndarray | None = None,
                    note: Note = _silent) -> tuple[np.ndarray, np.ndarray | None]:
    """Offline closed-set result rows (ids ``1..n_targets``) of detection rows, and each row's look margin where a
    look was learned (else None); ``params``: the online ``boxtrack``
    pass's parameters (``max_targets`` dropped); ``vel_noise``: its velocity noise when not boxtrack's own;
    ``shapes``, ``parts``: each detection's blob shape and parts vectors (the look learned from them weighs in; merged
    blobs' animals go on their parts). Too few detections for
    the offline assignment get the online closed set's result instead, said to ``note``."""
    online = {k: v for k, v in params.items() if k != "max_targets"}
    rows, look = closed_set_and_look(det_rows, n_targets, frame_rate, n_frames=n_frames, online=online,
                                     vel_noise=vel_noise, shapes=shapes, parts=parts, note=note)
    if len(rows) or not len(det_rows):
        return rows, look
    frames = len(np.unique(det_rows[:, 0]))
    note(f"note: {frames} frame(s) of detections are too few for the offline closed set; the online closed "
         f"set's result (boxtrack --targets {n_targets}) is written instead")
    rows = online_rows(det_rows, frame_rate, n_frames, vel_noise=vel_noise, **{**online, "max_targets": n_targets})
    return rows, None


def offline_sequences(path: Path, output: Path, n_targets: int, params: dict[str, Any], min_score: float,
                      use_length: bool = True, det_format: str = "auto", *, note: Note = _silent,
                      file_note: Note = _silent,
                      status: Callable[[str], AbstractContextManager[Any]] = lambda text: nullcontext()) -> list[Path]:
    """The offline closed set over every sequence at ``path`` into its result file under ``output`` (outputs checked
    writable first; ``use_length``: seqinfo.ini's seqLength bounds the frames); ``note``: the closed set's notes,
    ``file_note``: what was assumed of a file's layout; returns the files written."""
    from lookalike.pipeline.files import sequences_and_targets

    sequences, targets = sequences_and_targets(path, output)
    ensure_writable(targets)
    for seq, target in zip(sequences, targets):
        assert seq.det_path is not None
        length = seq.length if use_length else None
        det = table_rows(seq.det_path, min_score, length, f"seqLength in {seq.root / 'seqinfo.ini'}"
                         if seq.root is not None else "the length", det_format, note=file_note)
        n_frames = max((seq.length if use_length else None) or 0, int(det[:, 0].max(initial=0)))
        with status(f"closed set of {n_targets} on {seq.name}"):
            rows = closed_set_rows(det, n_targets, seq.frame_rate, n_frames, params, note=note)[0]
        write_mot(target, rows)
    return targets


def offline_rows(det: Path | np.ndarray, n_targets: int, params: dict[str, Any], frame_rate: float,
                 n_frames: int | None, min_score: float, det_format: str = "auto", shapes: np.ndarray | None = None,
                 parts: np.ndarray | None = None, *, note: Note = _silent, file_note: Note = _silent,
                 status: Callable[[str], AbstractContextManager[Any]] = lambda text: nullcontext()
                 ) -> tuple[np.ndarray, np.ndarray | None]:
    """The offline closed set of ``n_targets`` over a video's detections ``det`` (a detection file, or rows a
    detector found, with ``shapes`` and ``parts``: each row's blob shape and parts vectors, used when there is one a
    row kept), those below
    ``min_score`` dropped; ``frame_rate`` in frames/s. ``note`` and ``file_note`` as for :func:`offline_sequences`.
    Returns the rows and their look margins as :func:`closed_set_rows`."""
    rows = table_rows(det, min_score, det_format=det_format, note=file_note) if isinstance(det, Path) else \
        det[det[:, 6] >= min_score]
    shapes = shapes if shapes is not None and len(shapes) == len(rows) else None
    parts = parts if shapes is not None and parts is not None and len(parts) == len(rows) else None
    with status(f"closed set of {n_targets}" + (", learning each one's look" if shapes is not None else "")):
        return closed_set_rows(rows, n_targets, frame_rate, n_frames, params, shapes=shapes, parts=parts, note=note)


def offline_video(det: Path | np.ndarray, output: Path, n_targets: int, params: dict[str, Any], frame_rate: float,
                  n_frames: int | None, min_score: float, on_event: Callable[[Event], None], det_format: str = "auto",
                  *, video: Path | None = None, annotate: Path | None = None, annotate_as: Path | None = None,
                  shapes: np.ndarray | None = None, parts: np.ndarray | None = None) -> np.ndarray | None:
    """``track --video ... --offline``: the closed set over a video's detections (see :func:`offline_rows`) written
    to ``output``; with ``annotate``, its identities drawn on ``video`` into that MP4 (told as ``annotate_as``);
    what it does told to ``on_event``; returns the written rows' look margins as ``(frame, id, margin)`` rows where
    the closed set learned a look, else None. ``ValueError`` for a bad input or video."""
    line = telling(on_event, "line")
    fell_back: list[str] = []  # the note of a fall-back to the online closed set, if any

    def noted(text: str) -> None:
        fell_back.append(text)
        line(text)

    try:
        rows, look = offline_rows(det, n_targets, params, frame_rate, n_frames, min_score, det_format, shapes, parts,
                                  note=noted, file_note=telling(on_event, "note"), status=partial(step, on_event))
    except FileNotFoundError as exc:
        raise ValueError(str(exc)) from exc
    write_mot(output, rows)
    what = "online closed set (the note above)" if fell_back else "offline closed set"
    on_event(Event("result", f", {what} of {n_targets}: {len(np.unique(rows[:, 1]))} identities, "
                             f"{len(rows)} rows at {frame_rate:g} frames/s → {output}", name="boxtrack"))
    if annotate is not None and video is not None:
        draw_step(on_event, "drawing the identities", MotTable.from_rows(rows), annotate, frame_rate, video)
        line(f"annotated video → {annotate_as or annotate}")
    return None if look is None else np.column_stack([rows[:, :2], look])


def draw_step(on_event: Callable[[Event], None], what: str, *args: Any) -> None:
    """:func:`draw_tracks` (``args``) as the step ``what``; ``ValueError`` for a video that cannot be read."""
    try:
        with step(on_event, what):
            draw_tracks(*args)
    except OSError as exc:
        raise ValueError(str(exc)) from exc


def draw_tracks(tracks: MotTable, annotate: Path, frame_rate: float, video: Path | None = None,
                frames: int = 0) -> None:
    """Draw ``tracks`` on ``video`` (None: on ``frames`` white frames) into the MP4 ``annotate`` at ``frame_rate``
    frames/s."""
    from lookalike.viz.overlay import blank_frames, overlay_tracks

    overlay_tracks(video if video is not None else blank_frames(tracks, frames), tracks, annotate, fps=frame_rate)


def point_tracker(tracker: Any) -> Any:
    """``tracker`` for points as boxes: a ``boxtrack`` rebuilt with the points' velocity noise; others unchanged."""
    return BoxTrack(tracker.config, vel_noise=POINT_VEL_NOISE) if isinstance(tracker, BoxTrack) else tracker


def read_points(path: Path) -> Any:
    """Points of a ``frame,x,y`` CSV (``.csv``) or of MOTChallenge rows with a point per row (any other suffix)."""
    return read_points_csv(path) if path.suffix.lower() == ".csv" else read_points_mot(path)


@dataclass(frozen=True)
class PointBoxes:
    """Points as detection ``rows`` ``(k, 10)``: boxes of ``side`` px centred on them, over ``frames`` frames;
    ``count`` points, ``spacing`` their typical nearest-neighbour distance (px; 0 for one point a frame)."""

    rows: np.ndarray
    frames: int
    count: int
    spacing: float
    side: float
    zero_based: bool = False


def point_boxes(path: Path) -> PointBoxes:
    """The points of ``path`` as boxes of half their typical spacing; ``ValueError`` past
    :data:`MAX_POINTS_PER_FRAME` points in a frame."""
    points = read_points(path)
    counts = [len(p) for p in points.points]
    if counts and max(counts) > MAX_POINTS_PER_FRAME:
        frame = int(np.argmax(counts)) + 1
        raise ValueError(f"{path}: frame {frame} has {max(counts)} points; at most {MAX_POINTS_PER_FRAME} "
                         "a frame are tracked")
    spacing = typical_spacing(points)
    det = points_to_rows(points)
    return PointBoxes(det, len(points), points.count, spacing, float(det[0, 4]) if len(det) else 1.0,
                      points.zero_based)


def track_point_boxes(boxes: PointBoxes, output: Path, tracker: Any, frame_rate: float, n_targets: int | None = None,
                      params: dict[str, Any] | None = None, note: Note = _silent) -> np.ndarray:
    """Track ``boxes`` into the result file ``output``: online by ``tracker``, or with ``params`` (the online pass's)
    by the offline closed set of ``n_targets``; returns the result rows (their first two columns at least)."""
    if params is not None:
        assert n_targets is not None
        rows = closed_set_rows(boxes.rows, n_targets, frame_rate, boxes.frames, params, vel_noise=POINT_VEL_NOISE,
                               note=note)[0]
        write_mot(output, rows)
        return rows
    track_to_file(point_tracker(tracker), frames_from_table(MotTable.from_rows(boxes.rows), boxes.frames, frame_rate),
                  output)
    table = read_mot(output)
    return np.column_stack([table.frame, table.track_id]) if len(table) else np.zeros((0, 2))


__all__ = ["MAX_POINTS_PER_FRAME", "POINTS_FPS", "PointBoxes", "closed_set_rows", "draw_step", "draw_tracks",
           "offline_rows", "offline_sequences", "offline_video", "point_boxes", "point_tracker", "read_points",
           "table_rows", "track_point_boxes"]
