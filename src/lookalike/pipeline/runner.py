"""One entry for a ``lookalike track`` run: :func:`run` takes a :class:`~lookalike.pipeline.request.TrackRequest`,
tells what happens through ``on_event`` and returns what it wrote; the command line prints both."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from functools import partial
from pathlib import Path
from typing import TYPE_CHECKING, Any

from lookalike.loop import RunStats
from lookalike.pipeline import files
from lookalike.pipeline.request import TrackRequest

if TYPE_CHECKING:
    from lookalike.pipeline.tracking import VideoTrackingResult

BRANCHES = ("files", "video")
"""The branches :func:`run` takes (online trackers; see :meth:`TrackRequest.branch`)."""


@dataclass(frozen=True)
class Event:
    """Something a run tells as it goes. ``kind``: ``note`` (an assumption made), ``warn`` (something looks wrong),
    ``line`` (a plain line), ``start`` (a step named ``text`` of ``count`` frames, 0: unknown), ``advance`` (step
    ``text`` went ``count`` frames further) or ``end`` (step ``text`` is over)."""

    kind: str
    text: str = ""
    count: int = 0


@dataclass
class RunResult:
    """What :func:`run` did on ``branch``: the ``written`` files, the ``sequences`` tracked, the tracker's ``stats``
    (frames, seconds) and, on a video, the tracking pass's ``video`` result."""

    branch: str
    written: list[Path] = field(default_factory=list)
    sequences: int = 0
    stats: RunStats = field(default_factory=RunStats)
    video: VideoTrackingResult | None = None


def run(request: TrackRequest, on_event: Callable[[Event], None] | None = None) -> RunResult:
    """Run ``request`` (a branch of :data:`BRANCHES`, not offline) and return what it wrote; ``ValueError`` (bad
    options or inputs, one readable line) or ``OSError`` (an output that cannot be written)."""
    tell = on_event or (lambda event: None)
    branch = request.branch()
    if branch not in BRANCHES or request.is_offline(branch, request.live()):
        raise ValueError(f"lookalike.pipeline.run: takes the online {' and '.join(BRANCHES)} branches, not {branch}")
    tracker = files.box_tracker(request.tracker, request.settings, video=branch == "video",
                                targets=request.targets or None, params_file=request.params_file)
    if branch == "video":
        from lookalike.pipeline.video import run_video

        assert request.video_path is not None
        team_size = request.team_size if request.team_size is not None else request.targets or None
        return run_video(request.video_path, request.detections or request.path or Path(), request.output, tracker,
                         request.tracker, tell, annotate=request.annotate, team_size=team_size,
                         health_window=request.health_window, min_score=request.min_score, fps=request.fps,
                         features=request.features, det_format=request.det_format)
    return _track_files(request, tracker, tell)


def _track_files(request: TrackRequest, tracker: Any, tell: Callable[[Event], None]) -> RunResult:
    """Every sequence at ``request.path`` tracked into ``request.output`` (a file for one det.txt, else
    ``<output>/<sequence>.txt``), inputs checked and outputs decided first."""
    assert request.path is not None
    try:
        streams = files.open_sequences(request.path, request.output, request.min_score, request.use_length,
                                       request.det_format)
    except (FileNotFoundError, ValueError) as exc:
        raise ValueError(files.input_error(exc)) from exc
    for seq, frames, target in streams:
        files.sequence_warnings(seq, frames, target, lambda s: tell(Event("warn", s)),
                                lambda s: tell(Event("note", s)))
    result = RunResult("files", [target for _, _, target in streams], len(streams))
    tell(Event("start", "sequences", len(streams)))
    for seq, frames, target in streams:
        tell(Event("start", seq.name, frames.length))
        dropped = files.track_sequence(tracker, seq, frames, target, result.stats, partial(_advance, tell, seq.name),
                                       request.tracker)
        tell(Event("end", seq.name))
        tell(Event("advance", "sequences", 1))
        if dropped is not None:
            tell(Event("warn", dropped))
    tell(Event("end", "sequences"))
    return result


def _advance(tell: Callable[[Event], None], step: str, frames: int) -> None:
    tell(Event("advance", step, frames))


__all__ = ["BRANCHES", "Event", "RunResult", "run"]
