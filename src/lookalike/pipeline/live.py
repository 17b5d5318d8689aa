"""A live camera or stream (``lookalike track --video 0|URL``): checked before it is opened, then tracked until it
ends or is stopped (:mod:`lookalike.io.live`)."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any

from lookalike.io.needs import input_kind
from lookalike.pipeline.request import TrackRequest
from lookalike.pipeline.runner import Event, RunResult


def live_settings(spec: str, output: Path, tracker_name: str, detector: str, settings: list[str],
                  refused: dict[str, bool]) -> dict[str, Any]:
    """The blob detector's ``KEY=VALUE`` ``settings`` as values (none for an ONNX ``detector``); ``ValueError`` for
    options that do not apply to a live source (``refused``: name -> given), a tracker reading more than boxes, a
    folder as ``output`` or a detector that is neither ``blob`` nor an existing ``.onnx`` file."""
    given = [name for name, on in refused.items() if on]
    if given:
        raise ValueError(f"--video {spec}: a live source; drop {', '.join(given)} (see the live camera how-to)")
    if input_kind(tracker_name) != "boxes":
        raise ValueError(f"--video {spec}: a live source runs trackers that read boxes alone (boxtrack, sort), not "
                         f"{tracker_name!r}")
    if output.is_dir():
        raise ValueError(f"-o/--output: {output} is a folder; give a result file such as tracks.txt")
    if detector == "blob":
        from lookalike.pipeline.blob_detections import blob_settings

        return blob_settings(settings)
    if not detector.lower().endswith(".onnx"):
        raise ValueError(f"--detector: choose blob or FILE.onnx, got {detector!r}")
    if not Path(detector).is_file():
        raise ValueError(f"--detector: {detector} does not exist")
    return {}


def run_live(request: TrackRequest, on_event: Callable[[Event], None]) -> RunResult:
    """Track the live source ``request.video`` into ``request.output`` until it ends, ``max_frames``,
    ``seconds`` or Ctrl-C/SIGTERM (the file then holds every whole frame); what it does told to ``on_event``.
    ``ValueError`` or ``TypeError`` for a bad request or a source that cannot be opened."""
    from lookalike.io.live import LiveRun, LiveStop, prepare_live, track_live
    from lookalike.io.sources import open_live
    from lookalike.pipeline.files import box_tracker, tracker_params

    spec, output, name, detector = request.video or "", request.output, request.tracker, request.detector or ""
    refused = {"--annotate": request.annotate is not None, "--offline": bool(request.offline),
               "--features": request.features != "video", "--fps": request.fps is not None}
    blob = live_settings(spec, output, name, detector, request.blob, refused)
    given = tracker_params(name, request.settings, request.params_file)
    tracker = box_tracker(name, given, video=True, targets=request.targets or None)
    explicit = given.keys()
    try:
        with LiveStop() as stop:
            on_event(Event("busy", f"opening {spec}"))
            source = open_live(spec)
            on_event(Event("end", f"opening {spec}"))
            with source:
                if detector == "blob":
                    on_event(Event("line", f"{spec}: blob settings from the first frames (about 2 s)"))
                plan = prepare_live(source, detector, tracker, name, blob=blob, onnx=request.blob,
                                    n_targets=request.targets, explicit=explicit, min_score=request.min_score,
                                    stop=stop)
                for line in plan.estimate.summary.splitlines() if plan.estimate is not None else []:
                    on_event(Event("line", f"  {line}"))
                if plan.count is not None:
                    on_event(Event("line", plan.count.summary.replace("the video", "the first frames")))
                on_event(Event("busy", "tracking (Ctrl-C stops and keeps the result)", name="tracking"))

                def show(run: LiveRun) -> None:
                    if run.frames % 25 == 0:
                        on_event(Event("busy", f"tracking {spec}: {run.frames} frames, {run.fps:.1f} frames/s, "
                                               f"{source.dropped} dropped (Ctrl-C stops and keeps the result)",
                                       name="tracking"))

                run = track_live(source, plan, output, max_frames=request.max_frames, seconds=request.seconds,
                                 stop=stop, on_frame=show)
                on_event(Event("end", "tracking"))
    except OSError as exc:
        raise ValueError(str(exc)) from exc
    setup = f" ({run.dropped_before} while setting up)" if run.dropped_before else ""
    on_event(Event("result", f": {run.frames} frames in {run.wall_s:.1f} s ({run.fps:.1f} frames/s; detector + "
                             f"tracker {run.busy_fps:,.0f} frames/s), {run.dropped} of {run.delivered} dropped while "
                             f"busy{setup}, times from the {run.clock}; stopped: {run.stopped} → {output}", name=name))
    failed = run.stopped.startswith(("error: ", "source error: "))
    return RunResult("live", [output], 1, failure=run.stopped if failed else None)


__all__ = ["live_settings", "run_live"]
