"""``lookalike track --video FILE --pipeline robots``: robot identities from a video's pixels, and
``lookalike render-robots``: a simulated robot sequence drawn as a video through the camera.

The pipeline (:class:`lookalike.vision.pipeline.RobotPipeline`) detects robots with the HOG cascade,
estimates their headings, projects the boxes to the ground through the default robot camera
(:meth:`lookalike.geometry.Camera.default`: 640×480, 70° field of view, 0.9 m high, 25° down) and
identifies them with the heading reports of a ``lookalike simulate`` file (``--reports``: its
received beacons, frame times and observer yaw, frame k of the file belonging to frame k of the
video). The models are the shipped ones unless ``--detector-model``/``--heading-model`` name others.
Not a command of its own: ``lookalike track`` hands over here.
"""

from __future__ import annotations

import dataclasses
import math
import time
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

import numpy as np
import typer
from rich.progress import (
    BarColumn,
    MofNCompleteColumn,
    Progress,
    TextColumn,
    TimeElapsedColumn,
)

from lookalike.cli.app import app, console, fail
from lookalike.geometry.camera import Camera, Pose2D
from lookalike.io import write_mot
from lookalike.io.robot_sequences import read_robot_sequence
from lookalike.sim import RobotSequence, RobotWorldConfig
from lookalike.trackers import tracker_parameters
from lookalike.trackers.registry import parse_parameter
from lookalike.vision.pipeline import (
    IDENTIFIERS,
    PipelineConfig,
    PipelineResult,
    RobotPipeline,
    labelled_rows,
)

PIPELINES = ("robots",)


def pixel_camera() -> Camera:
    """The camera the robots are rendered and identified with (the detector and heading models' own)."""
    return Camera.default()


def hfov_rad(camera: Camera) -> float:
    """Horizontal field of view of ``camera`` (rad)."""
    k = camera.intrinsics
    return 2.0 * math.atan(0.5 * k.width / k.fx)


def world_for_camera(config: RobotWorldConfig, camera: Camera) -> RobotWorldConfig:
    """``config`` with the observer's field of view set to the camera's, so that the simulator's own
    detections and the pixels see the same robots."""
    return dataclasses.replace(config, observer=dataclasses.replace(config.observer, fov_rad=hfov_rad(camera)))


def identifier_settings(name: str, camera: Camera) -> tuple[tuple[str, Any], ...]:
    """Parameters that tie identifier ``name`` to the camera (its field of view, for out-of-view coasting)."""
    known = {p.name for p in tracker_parameters(name)}
    return (("fov_deg", math.degrees(hfov_rad(camera))),) if "fov_deg" in known else ()


@contextmanager
def one_blas_thread() -> Iterator[None]:
    """Limit BLAS to one thread inside the block (threadpoolctl, when installed): the heading SVM's small matrix
    products run several times faster so than spread over the threads of a busy machine."""
    try:
        from threadpoolctl import threadpool_limits
    except ImportError:
        yield
        return
    with threadpool_limits(limits=1, user_api="blas"):
        yield


def render_robot_frames(sequence: RobotSequence, camera: Camera, seed: int) -> Iterator[Any]:
    """The :class:`~lookalike.sim.render_robots.RenderedFrame` of every frame of ``sequence``, seen from
    its observer pose (robots at their field positions with their absolute headings)."""
    from lookalike.sim.render_robots import RenderConfig, RobotRenderer

    a = sequence.arrays
    renderer = RobotRenderer(camera=camera, config=RenderConfig(field_m=sequence.config.field_m), seed=seed)
    for k in range(len(a)):
        pose = a.observer[k]
        yield renderer.render(a.field_position[k], a.true_heading[k], Pose2D(*(float(v) for v in pose)))


def annotate_frame(image: np.ndarray, result: PipelineResult, caption: list[str]) -> np.ndarray:
    """A copy of ``image`` with each detection boxed in its identity colour (dashed grey: false positive)."""
    from lookalike.viz.annotate import draw_box, draw_caption
    from lookalike.viz.colors import identity_colour

    out = image.copy()
    det = result.detections
    for box, lab, pos in zip(det.xywh, result.labels, det.position):
        text = "false positive" if lab < 0 else f"robot {lab} {pos[0]:.1f},{pos[1]:.1f} m"
        draw_box(out, box, identity_colour(int(lab)), label=text, dashed=lab < 0)
    draw_caption(out, caption)
    return out


def run_track_pixels(video: Path | None, output: Path, pipeline: str, reports: Path | None, detector_model: Path | None,
                     heading_model: Path | None, identifier: str, settings: list[str], *,
                     annotate: Path | None = None, fps: float | None = None, min_score: float = 0.5) -> None:
    """Run pipeline ``pipeline`` over ``video`` with the reports of ``reports``; write MOTChallenge rows
    (``frame, robot id + 1, box, identity confidence, ground x, y (m), -1``) to ``output`` and, with
    ``annotate``, an annotated MP4. ``min_score``: detector probability threshold (-inf: 0.5)."""
    from lookalike.viz.overlay import source_frames
    from lookalike.viz.video import VideoWriter

    if video is None:
        fail("--pipeline: give the video with --video FILE")
    if min_score == float("-inf"):
        min_score = 0.5
    if pipeline not in PIPELINES:
        fail(f"--pipeline: choose one of {', '.join(PIPELINES)}, got {pipeline!r}")
    if reports is None:
        fail("--pipeline robots: needs --reports (the heading reports: a `lookalike simulate` .jsonl)")
    if identifier not in IDENTIFIERS:
        fail(f"--tracker: with --pipeline robots choose an identifier: {', '.join(IDENTIFIERS)} (got {identifier!r})")
    if output.is_dir():
        fail(f"-o/--output: {output} is a folder; give a result file such as tracks.txt")
    camera = pixel_camera()
    try:
        seq = read_robot_sequence(reports)
        params = identifier_settings(identifier, camera) + tuple(parse_parameter(identifier, s) for s in settings)
        config = PipelineConfig(identifier=identifier, n_agents=seq.config.n_agents,
                                max_detections=seq.config.max_detections, min_score=min_score,
                                identifier_params=tuple(dict(params).items()))
        pipe = RobotPipeline.from_files(detector_model, heading_model, camera, config)
        frames, total, video_fps = source_frames(video)
    except (ValueError, FileNotFoundError, OSError, TypeError) as exc:
        fail(str(exc))
    if total and total > len(seq):
        fail(f"--reports: {reports} has {len(seq)} frames but the video has {total}")
    rows, elapsed, n = [], 0.0, 0
    columns = (TextColumn("identifying robots"), BarColumn(), MofNCompleteColumn(), TimeElapsedColumn())
    writer = VideoWriter(annotate, fps=fps or video_fps) if annotate is not None else None
    try:
        with Progress(*columns, console=console, transient=True) as progress, one_blas_thread():
            task = progress.add_task(video.name, total=total or None)
            for k, image in enumerate(frames):
                if k >= len(seq):
                    fail(f"--reports: {reports} has {len(seq)} frames, the video more")
                frame = seq.frame(k)
                t0 = time.perf_counter()
                result = pipe.update(image, frame.beacons, frame.time, float(seq.arrays.observer[k, 2]))
                elapsed += time.perf_counter() - t0
                rows.append(labelled_rows(k, result.detections, result.labels, result.tracks))
                if writer is not None:
                    writer.write(annotate_frame(image, result, [
                        f"{identifier} from pixels, {seq.config.n_agents} robots",
                        f"frame {k + 1}  t = {frame.time:.2f} s  {len(result.detections)} detection(s)"]))
                n += 1
                progress.advance(task)
    except ValueError as exc:
        fail(f"{video}: {exc}")
    finally:
        if writer is not None:
            writer.close()
    write_mot(output, rows)
    speed = f"{n / elapsed:,.1f}" if elapsed > 0 else "inf"
    console.print(f"[green]{identifier}[/] from pixels: {n} frames, {speed} frames/s (detector + heading + "
                  f"identifier) → {output}" + (f", {annotate}" if annotate else ""))


@app.command("render-robots")
def render_robots(
    sequence: Path = typer.Argument(..., help="A robot sequence written by `lookalike simulate` (.jsonl)."),
    output: Path = typer.Option(..., "-o", "--output", help="MP4 to write."),
    seed: int = typer.Option(0, help="Seed of the lighting, blur and pixel noise."),
) -> None:
    """Draw a simulated robot sequence through the robot camera (640×480, 70°) as a video: the input of
    `lookalike track --video FILE --pipeline robots --reports SEQUENCE`."""
    from lookalike.viz.video import VideoWriter

    try:
        seq = read_robot_sequence(sequence)
    except (ValueError, FileNotFoundError, OSError) as exc:
        fail(str(exc))
    columns = (TextColumn("rendering"), BarColumn(), MofNCompleteColumn(), TimeElapsedColumn())
    with Progress(*columns, console=console, transient=True) as progress, \
            VideoWriter(output, fps=seq.config.frame_rate_hz) as writer:
        task = progress.add_task("render", total=len(seq))
        for frame in render_robot_frames(seq, pixel_camera(), seed):
            writer.write(frame.image)
            progress.advance(task)
    console.print(f"wrote {output} ({len(seq)} frames)")
