"""``lookalike track --video 0|URL``: a live camera or stream (:mod:`lookalike.io.live`), options checked and the
run's totals printed."""

from __future__ import annotations

from collections.abc import Collection
from pathlib import Path
from typing import Any

from rich.markup import escape

from lookalike.cli.app import console, failing
from lookalike.io.live import LiveRun, LiveStop, prepare_live, track_live
from lookalike.io.sources import open_live
from lookalike.pipeline.live import live_settings


def run_track_live(spec: str, output: Path, tracker: Any, tracker_name: str, detector: str,
                   settings: list[str], *, n_targets: int | None, explicit: Collection[str], min_score: float,
                   max_frames: int | None, seconds: float | None, refused: dict[str, bool]) -> None:
    """Track the live source ``spec`` into ``output`` until it ends, ``max_frames``, ``seconds`` or Ctrl-C/SIGTERM;
    ``refused``: options that do not apply to a live source (name -> given)."""
    with failing(ValueError):
        blob = live_settings(spec, output, tracker_name, detector, settings, refused)
    with failing(ValueError, OSError), LiveStop() as stop:
        with console.status(f"opening {escape(spec)}"):
            source = open_live(spec)
        with source:
            if detector == "blob":
                console.print(f"{escape(spec)}: blob settings from the first frames (about 2 s)")
            plan = prepare_live(source, detector, tracker, tracker_name, blob=blob, onnx=settings,
                                n_targets=n_targets, explicit=explicit, min_score=min_score, stop=stop)
            if plan.estimate is not None:
                for line in plan.estimate.summary.splitlines():
                    console.print(f"  {line}", markup=False)
            if plan.count is not None:
                console.print(plan.count.summary.replace("the video", "the first frames"), markup=False)
            with console.status("tracking (Ctrl-C stops and keeps the result)") as status:
                def show(run: LiveRun) -> None:
                    if run.frames % 25 == 0:
                        status.update(f"tracking {escape(spec)}: {run.frames} frames, {run.fps:.1f} frames/s, "
                                      f"{source.dropped} dropped (Ctrl-C stops and keeps the result)")

                run = track_live(source, plan, output, max_frames=max_frames, seconds=seconds, stop=stop,
                                 on_frame=show)
    setup = f" ({run.dropped_before} while setting up)" if run.dropped_before else ""
    console.print(f"[green]{tracker_name}[/]: {run.frames} frames in {run.wall_s:.1f} s ({run.fps:.1f} frames/s; "
                  f"detector + tracker {run.busy_fps:,.0f} frames/s), {run.dropped} of {run.delivered} dropped "
                  f"while busy{setup}, times from the {run.clock}; stopped: {escape(run.stopped)} → "
                  f"{escape(str(output))}")
