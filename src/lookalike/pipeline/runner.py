"""One entry for a ``lookalike track`` run: :func:`run` takes a :class:`~lookalike.pipeline.request.TrackRequest`,
tells what happens through ``on_event`` and returns what it wrote; the command line prints both."""

from __future__ import annotations

from collections.abc import Callable, Collection, Iterator
from contextlib import ExitStack, contextmanager
from dataclasses import dataclass, field
from functools import partial
from pathlib import Path
from typing import TYPE_CHECKING, Any

from lookalike.io.outputs import atomic_path
from lookalike.loop import RunStats, expect
from lookalike.pipeline import files
from lookalike.pipeline.request import TrackRequest

if TYPE_CHECKING:
    import numpy as np

    from lookalike.pipeline.tracking import VideoTrackingResult

BRANCHES = ("files", "video", "points", "blobs", "pipeline")
"""The branches :func:`run` takes (see :meth:`TrackRequest.branch`), online or ``--offline``; a live source is
tracked on the ``blobs`` branch (:func:`lookalike.pipeline.live.run_live`)."""


@dataclass(frozen=True)
class Event:
    """Something a run tells as it goes. ``kind``: ``note`` (an assumption made), ``warn`` (something looks wrong),
    ``line`` (a plain line), ``result`` (what the tracker ``name`` wrote: the line's text after the name), ``start``
    (a step named ``text`` of ``count`` frames, 0: unknown), ``advance`` (step ``text`` went ``count`` frames
    further), ``busy`` (a step that tells no progress, named ``name`` or else ``text``; told again with the same
    ``name``, its ``text`` changes) or ``end`` (the step named ``text`` is over)."""

    kind: str
    text: str = ""
    count: int = 0
    name: str = ""


@dataclass
class RunResult:
    """What :func:`run` did on ``branch``: the ``written`` result files, the tracker's ``stats`` (frames, seconds;
    online file runs), on a video tracked online the tracking pass's ``video`` result, and per result file of a
    closed set that learned a look its rows' look margins (``looks``: ``(frame, id, margin)`` rows); ``failure``: why a
    live run ended early on an error (its file holds every frame tracked before), None when it did not."""

    branch: str
    written: list[Path] = field(default_factory=list)
    sequences: int = 0
    stats: RunStats = field(default_factory=RunStats)
    video: VideoTrackingResult | None = None
    looks: dict[Path, np.ndarray] = field(default_factory=dict)
    failure: str | None = None


def run(request: TrackRequest, on_event: Callable[[Event], None] | None = None) -> RunResult:
    """Run ``request`` (a branch of :data:`BRANCHES`; its options and outputs checked first) and return what it
    wrote, each result row's identity confidence in column 7 (:mod:`lookalike.pipeline.results`; not for robots or
    live sources), the doubtful ranges told as lines; the ``annotate`` MP4 appears whole or not at all.
    ``ValueError`` or ``TypeError`` (bad options or inputs, one readable line), ``OSError`` (an output that cannot
    be written)."""
    tell = on_event or (lambda event: None)
    live = request.live()
    branch = request.branch()
    offline = request.is_offline(branch, live)
    request.check_outputs([request.path, request.video_path, request.detections, request.points, request.reports,
                           request.params_file, request.detector_model, request.heading_model])
    if live is not None:
        from lookalike.pipeline.live import run_live

        return run_live(request, tell)  # (rows written as they come: no confidence column)
    with ExitStack() as stack:
        annotate = None if request.annotate is None else stack.enter_context(atomic_path(request.annotate))
        if branch == "pipeline":
            from lookalike.pipeline.robots import run_robots

            return run_robots(request, annotate, tell)
        given = files.tracker_params(request.tracker, request.settings, request.params_file)  # (parsed once)
        tracker = files.box_tracker(request.tracker, given, video=branch in ("video", "blobs"),
                                    targets=request.targets or None)
        params = given if offline else None
        if branch in ("points", "video", "blobs"):
            run_branch: dict[str, Callable[..., RunResult]] = {
                "points": _points, "video": _video, "blobs": partial(_detected, explicit=given.keys())}
            result = run_branch[branch](request, tracker, params, annotate, tell)
        else:
            result = _offline_files(request, params, tell) if params is not None else _files(request, tracker, tell)
    result.branch = branch
    from lookalike.pipeline.results import add_confidence, written_results

    found = written_results(branch, request.path, request.output, request.video_path, request.fps)
    for line in add_confidence(found, result.looks):  # each row's identity confidence in column 7
        tell(Event("line", line))
    return result


@contextmanager
def step(on_event: Callable[[Event], None], text: str) -> Iterator[None]:
    """A step named ``text`` that tells no progress, told to ``on_event`` as it starts and ends."""
    on_event(Event("busy", text))
    yield
    on_event(Event("end", text))


def _where(request: TrackRequest) -> str:
    assert request.path is not None
    return str(request.output) if request.path.is_file() else f"{request.output}/<sequence>.txt"


def _files(request: TrackRequest, tracker: Any, tell: Callable[[Event], None]) -> RunResult:
    """Every sequence at ``request.path`` tracked into ``request.output`` (a file for one det.txt, else
    ``<output>/<sequence>.txt``), inputs checked and outputs decided first."""
    assert request.path is not None
    try:
        streams = files.open_sequences(request.path, request.output, request.min_score, request.use_length,
                                       request.det_format)
    except (FileNotFoundError, ValueError) as exc:
        raise ValueError(files.input_error(exc)) from exc
    for seq, frames, target in streams:
        files.sequence_warnings(seq, frames, target, telling(tell, "warn"), telling(tell, "note"))
    result = RunResult("files", [target for _, _, target in streams], len(streams))
    expect(tracker, sum(frames.length or 0 for _, frames, _ in streams))
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
    stats = result.stats
    speed = f", {stats.fps:,.0f} frames/s (tracker only)" if stats.frames and stats.seconds > 0 else ""
    tell(Event("result", f": {len(streams)} sequence(s), {stats.frames} frames{speed} → {_where(request)}",
               name=request.tracker))
    return result


def _offline_files(request: TrackRequest, params: dict[str, Any], tell: Callable[[Event], None]) -> RunResult:
    """``--offline`` over every sequence at ``request.path`` (outputs decided first)."""
    from lookalike.pipeline.closed import offline_sequences

    assert request.path is not None and request.targets
    try:
        written = offline_sequences(request.path, request.output, request.targets, params, request.min_score,
                                    request.use_length, request.det_format, note=telling(tell, "line"),
                                    file_note=telling(tell, "note"), status=partial(step, tell))
    except (FileNotFoundError, ValueError) as exc:
        raise ValueError(files.input_error(exc)) from exc
    except OSError as exc:
        raise ValueError(f"output {request.output}: cannot write ({exc.strerror or exc})") from exc
    tell(Event("result", f", offline closed set of {request.targets}: {len(written)} sequence(s) → "
                         f"{_where(request)}", name=request.tracker))
    return RunResult("files", written, len(written))


def _video(request: TrackRequest, tracker: Any, params: dict[str, Any] | None, annotate: Path | None,
           tell: Callable[[Event], None]) -> RunResult:
    """A video and its detections: tracked online, or with ``params`` (the online pass's) by the offline closed
    set."""
    from lookalike.pipeline.video import check_result_file, run_video

    video, det = request.video_path, request.detections or request.path
    assert video is not None and det is not None
    if params is None:
        return run_video(video, det, request.output, tracker, request.tracker, tell, annotate=annotate,
                         team_size=request.health_team_size, health_window=request.health_window,
                         min_score=request.min_score, fps=request.fps, features=request.features,
                         det_format=request.det_format, annotate_as=request.annotate)
    from lookalike.io.video_frames import source_frames
    from lookalike.pipeline.closed import offline_video

    assert request.targets
    check_result_file(request.output)
    try:
        _, count, rate = source_frames(video)
    except OSError as exc:
        raise ValueError(str(exc)) from exc
    offline_video(det, request.output, request.targets, params, request.fps or rate, count or None, request.min_score,
                  tell, request.det_format, video=video, annotate=annotate, annotate_as=request.annotate)
    return RunResult("video", [request.output], 1)


def _detected(request: TrackRequest, tracker: Any, params: dict[str, Any] | None, annotate: Path | None,
              tell: Callable[[Event], None], explicit: Collection[str] = ()) -> RunResult:
    """A video's boxes found by ``request.detector`` (``blob`` or an ONNX model), then tracked (``explicit``: the
    tracker parameters given, kept as given)."""
    from lookalike.pipeline.blobs import run_blobs
    from lookalike.pipeline.video import run_onnx

    video, detector = request.video_path, request.detector or ""
    assert video is not None
    options: dict[str, Any] = dict(annotate=annotate, annotate_as=request.annotate, team_size=request.health_team_size,
                                   min_score=request.min_score, health_window=request.health_window, fps=request.fps,
                                   features=request.features, save_detections=request.save_detections,
                                   n_targets=request.targets, offline=params)
    if detector.lower().endswith(".onnx"):
        return run_onnx(video, request.output, tracker, request.tracker, Path(detector), request.blob, tell, **options)
    if detector != "blob":
        raise ValueError(f"--detector: choose one of blob or FILE.onnx, got {detector!r}")
    return run_blobs(video, request.output, tracker, request.tracker, request.blob, tell, explicit=explicit,
                     **options)


def _points(request: TrackRequest, tracker: Any, params: dict[str, Any] | None, annotate: Path | None,
            tell: Callable[[Event], None]) -> RunResult:
    """Points as boxes of half their typical spacing, tracked online by ``tracker`` or, with ``params``, by the
    offline closed set; the tracks drawn on ``request.video`` (or white frames) with ``annotate``."""
    import numpy as np

    from lookalike.io import read_mot
    from lookalike.pipeline.closed import POINTS_FPS, draw_step, point_boxes, track_point_boxes

    output, points = request.output, request.points
    assert points is not None
    if output.is_dir():
        raise ValueError(f"-o/--output: {output} is a folder; with --points give a result file such as tracks.txt")
    frame_rate = request.fps or POINTS_FPS
    try:
        boxes = point_boxes(points)
    except FileNotFoundError as exc:
        raise ValueError(str(exc)) from exc
    why = f"half the typical spacing {boxes.spacing:.3g}" if boxes.spacing > 0 else \
        "one point a frame: twice the typical step"
    if boxes.zero_based:
        tell(Event("note", f"{points}: frames start at 0: read as 0-based (file frame 0 is the first frame)"))
    tell(Event("line", f"points: {boxes.count} in {boxes.frames} frames, boxes of {boxes.side:.3g} ({why}), "
                       f"{frame_rate:g} frames/s" + ("" if request.fps else " (--fps to change)")))
    rows = track_point_boxes(boxes, output, tracker, frame_rate, request.targets or None, params,
                             note=telling(tell, "line"))
    what = f"offline closed set of {request.targets}" if params is not None else "online"
    tell(Event("result", f", {what}: {len(np.unique(rows[:, 1]))} identities → {output}", name=request.tracker))
    if annotate is not None:
        draw_step(tell, "drawing the tracks", read_mot(output), annotate, frame_rate, request.video_path, boxes.frames)
        tell(Event("line", f"annotated video → {request.annotate}"))
    return RunResult("points", [output], 1)


def telling(on_event: Callable[[Event], None], kind: str) -> Callable[[str], None]:
    """A callable telling ``on_event`` each line it is given as an event of ``kind``."""
    return lambda text: on_event(Event(kind, text))


def _advance(on_event: Callable[[Event], None], name: str, frames: int) -> None:
    on_event(Event("advance", name, frames))


__all__ = ["BRANCHES", "Event", "RunResult", "run", "step", "telling"]
