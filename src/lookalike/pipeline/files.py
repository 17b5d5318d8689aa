"""Trackers built from their options, and detection files tracked sequence by sequence (``lookalike track PATH``)."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any

from lookalike.io import find_sequences
from lookalike.io.det_format import det_warnings
from lookalike.io.needs import box_input_problem
from lookalike.io.outputs import ensure_writable, result_paths
from lookalike.io.stream import sequence_stream, track_to_file
from lookalike.loop import RunStats
from lookalike.trackers import make_tracker, tracker_names, tracker_parameters
from lookalike.trackers.registry import parse_parameter

LENGTH_HINT = " (--no-seqinfo-length tracks every frame in the file)"
BAR_STEP = 25
"""Frames between two calls of :func:`track_sequence`'s ``advance``."""


def tracker_params(name: str, settings: list[str], params_file: Path | None = None) -> dict[str, Any]:
    """A tracker's parameters: those of the ``lookalike tune`` file ``params_file`` (if any), then the ``KEY=VALUE``
    ``settings`` on top; ``ValueError`` or ``TypeError`` with a readable message."""
    if name not in tracker_names():
        raise ValueError(f"unknown tracker {name!r}; choose one of: {', '.join(tracker_names())}")
    base: dict[str, Any] = {}
    if params_file is not None:
        from lookalike.tune.params_file import load_params  # imported when used: keeps the CLI's start-up short

        base = load_params(params_file, name)
    return {**base, **dict(parse_parameter(name, s) for s in settings)}


def build_tracker(name: str, settings: list[str], params_file: Path | None = None) -> Any:
    """A tracker from its name, an optional ``lookalike tune`` parameter file and ``KEY=VALUE`` settings (which win);
    ``ValueError`` or ``TypeError`` with a readable message."""
    return make_tracker(name, **tracker_params(name, settings, params_file))


def box_tracker(name: str, params: dict[str, Any], *, video: bool = False, targets: int | None = None) -> Any:
    """A tracker of its parameters ``params`` (:func:`tracker_params`) that can run on boxes (``video``: from a
    video's detections), ``targets`` its ``max_targets``; ``ValueError`` or ``TypeError`` otherwise."""
    if targets is not None:
        if "max_targets" not in {p.name for p in tracker_parameters(name)}:
            raise ValueError(f"--targets: tracker {name!r} has no closed-set mode (max_targets); use -t boxtrack")
        params = {**params, "max_targets": targets}
    tracker = make_tracker(name, **params)
    problem = box_input_problem(name, video=video)
    if problem is not None:
        raise ValueError(problem)
    return tracker


def input_error(exc: Exception) -> str:
    """One line for a bad input; the seqLength rule names the option that lifts it."""
    message = str(exc)
    return message + LENGTH_HINT if "(seqLength in" in message else message


def sequences_and_targets(path: Path, output: Path) -> tuple[list[Any], list[Path]]:
    """The sequences with detections at ``path`` and their result files under ``output``."""
    sequences = [s for s in find_sequences(path) if s.det_path is not None]
    if not sequences:
        raise ValueError(f"{path}: no det/det.txt found")
    return sequences, result_paths(path, sequences, output)


def dropped_all(tracker: str, det_path: Path | str | None, rows: int, scores: tuple[float, float] | None) -> str:
    """The warning for a tracker that wrote no tracks from ``rows`` detections scoring ``scores``."""
    span = f" (scores {scores[0]:g} to {scores[1]:g})" if scores is not None else ""
    return (f"{tracker} wrote no tracks from the {rows} detections of {det_path}{span}: its score thresholds, the "
            f"frames a track needs before it is reported (`lookalike trackers --details {tracker}`) or --min-score "
            f"may drop them all, or the columns are not what they seem (--det-format)")


def open_sequences(path: Path, output: Path, min_score: float, use_length: bool = True,
                   det_format: str = "auto") -> list[tuple[Any, Any, Path]]:
    """Each sequence at ``path`` with its frame stream and result file (outputs checked writable first); ``use_length``:
    seqinfo.ini's seqLength bounds the frames. ``ValueError``/``FileNotFoundError`` for a bad input."""
    sequences, targets = sequences_and_targets(path, output)
    streams = [(seq, sequence_stream(seq, min_score, use_length, det_format), target)
               for seq, target in zip(sequences, targets)]
    ensure_writable(targets)
    return streams


def sequence_warnings(seq: Any, frames: Any, target: Path, warn: Callable[[str], None],
                      note: Callable[[str], None]) -> None:
    """Tell ``note`` what was assumed of ``seq``'s detection file and ``warn`` what looks wrong in it."""
    for line in frames.notes:
        note(line)
    if frames.rows == 0:
        warn(f"{seq.det_path}: no detections; {target} will hold no tracks")
    size_from = f"imWidth, imHeight in {seq.root / 'seqinfo.ini'}" if seq.root is not None else ""
    for line in det_warnings(seq.det_path or "", frames.rows, frames.scores, frames.outside, seq.image_size, size_from,
                             frames.largest):
        warn(line)


def track_sequence(tracker: Any, seq: Any, frames: Any, target: Path, stats: RunStats,
                   advance: Callable[[int], None] | None = None, name: str = "") -> str | None:
    """Track one of :func:`open_sequences`' streams (``seq``, ``frames``) into ``target`` with ``tracker`` reset,
    adding to ``stats``; ``advance(BAR_STEP)`` every :data:`BAR_STEP` frames. Returns the warning for a tracker
    (named ``name``) that wrote no tracks, else None; ``ValueError`` naming the sequence or the result file."""
    tracker.reset()

    def step(f: Any, t: Any) -> None:
        if advance is not None and f.index % BAR_STEP == BAR_STEP - 1:
            advance(BAR_STEP)

    try:
        track_to_file(tracker, frames, target, step, stats)
    except ValueError as exc:
        raise ValueError(f"{seq.name}: {input_error(exc)}") from exc
    except OSError as exc:
        raise ValueError(f"output {target}: cannot write ({exc.strerror or exc})") from exc
    if frames.rows and target.is_file() and target.stat().st_size == 0:
        return dropped_all(name or type(tracker).__name__, seq.det_path, frames.rows, frames.scores)
    return None


__all__ = ["BAR_STEP", "box_tracker", "build_tracker", "dropped_all", "input_error", "open_sequences",
           "sequence_warnings", "sequences_and_targets", "track_sequence", "tracker_params"]
