"""Robot identities from pixels (``lookalike track --video FILE --pipeline robots``, ``lookalike track --bag DIR``):
the detector, heading estimator and identifier of :class:`lookalike.vision.pipeline.RobotPipeline` fed a video's
(or a rosbag2 folder's) frames with the robots' heading reports, MOTChallenge rows written."""

from __future__ import annotations

from collections.abc import Callable, Iterable, Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from lookalike.io.robot_sequences import read_robot_sequence
from lookalike.io.stream import MotWriter
from lookalike.loop import RunStats
from lookalike.loop import run as run_loop
from lookalike.parallel import one_blas_thread
from lookalike.pipeline.request import TrackRequest
from lookalike.pipeline.runner import Event, RunResult
from lookalike.sim import RobotSequence
from lookalike.sim.robot_camera import identifier_settings, pixel_camera
from lookalike.trackers.registry import parse_parameter
from lookalike.types import Frame
from lookalike.vision.pipeline import IDENTIFIERS, PipelineConfig, PipelineResult, RobotPipeline, labelled_rows
from lookalike.viz.robot_pixels import annotate_frame, render_robot_frames

PIPELINES = ("robots",)
SIZE_TOLERANCE = 2.0  # box height vs a robot's at its ground position; true boxes 0.79-1.48 on m5n3 seeds 11-12


def check_robots(video: Path | None, pipeline: str, reports: Path | None, identifier: str, output: Path,
                 bag: Path | None = None, camera_topic: str | None = None) -> str:
    """The identifier to run (``sort``, ``track``'s default, becomes ``set``); ``ValueError`` naming the option when
    the inputs do not make a robots run: a ``video`` and its ``reports``, or a ``bag`` and its ``camera_topic``."""
    identifier = "set" if identifier == "sort" else identifier
    if video is None and bag is None:
        raise ValueError("--pipeline: give the video with --video FILE")
    if pipeline not in PIPELINES:
        raise ValueError(f"--pipeline: choose one of {', '.join(PIPELINES)}, got {pipeline!r}")
    if reports is None and bag is None:
        raise ValueError("--pipeline robots: needs --reports (the heading reports: a `lookalike simulate` .jsonl)")
    if identifier not in IDENTIFIERS:
        raise ValueError(f"--tracker: with --pipeline robots choose an identifier: {', '.join(IDENTIFIERS)} "
                         f"(got {identifier!r})")
    if output.is_dir():
        raise ValueError(f"-o/--output: {output} is a folder; give a result file such as tracks.txt")
    if bag is not None and camera_topic is None:
        raise ValueError("--bag: give --camera-topic (the sensor_msgs/Image topic the pipeline reads)")
    return identifier


@dataclass
class RobotRun:
    """A robots run ready to start: ``pipe`` to be fed ``images`` (``total`` frames, 0: unknown, at ``fps`` frames/s)
    of ``source`` with the heading reports ``seq`` (read from ``reports``); ``identifier``: the identifier's name."""

    identifier: str
    source: Path
    reports: Path
    seq: RobotSequence
    pipe: RobotPipeline
    images: Iterable[np.ndarray]
    total: int
    fps: float


def prepare_robots(video: Path | None, reports: Path | None, identifier: str, settings: list[str],
                   detector_model: Path | None, heading_model: Path | None, min_score: float = 0.5, *,
                   bag: Path | None = None, camera_topic: str | None = None,
                   heading_topics: str | None = None) -> RobotRun:
    """Read the reports (``reports``, or the rosbag2 folder ``bag``: images of ``camera_topic``, headings of the
    comma-separated ``heading_topics``), load the models (None: the shipped ones) and open the frames; ``settings``:
    the identifier's ``KEY=VALUE``; ``min_score``: detector probability (-inf: 0.5). Raises ``ValueError``,
    ``OSError`` or ``TypeError`` for a bad input."""
    from lookalike.io.video_frames import source_frames

    camera = pixel_camera()
    if bag is not None:
        from lookalike.io.rosbag import bag_images, read_bag

        topics = [t.strip() for t in heading_topics.split(",") if t.strip()] if heading_topics else None
        seq = read_bag(bag, camera_topic, topics).sequence
    else:
        assert reports is not None
        seq = read_robot_sequence(reports)
    params = identifier_settings(identifier, camera) + tuple(parse_parameter(identifier, s) for s in settings)
    config = PipelineConfig(identifier=identifier, n_agents=seq.config.n_agents,
                            max_detections=seq.config.max_detections,
                            min_score=0.5 if min_score == float("-inf") else min_score,
                            identifier_params=tuple(dict(params).items()), field_m=seq.config.field_m,
                            max_range_m=seq.config.observer.max_range_m, size_tolerance=SIZE_TOLERANCE)
    pipe = RobotPipeline.from_files(detector_model, heading_model, camera, config)
    if bag is not None:
        images, total, fps = bag_images(bag, camera_topic or ""), len(seq), seq.config.frame_rate_hz
    else:
        assert video is not None
        images, total, fps = source_frames(video)
    if total and total > len(seq):
        raise ValueError(f"--reports: {reports} has {len(seq)} frames but the video has {total}")
    source = bag if bag is not None else video
    assert source is not None
    return RobotRun(identifier, source, reports or source, seq, pipe, images, total, fps)


@dataclass(frozen=True)
class PixelFrame:
    """One video frame with the sequence's frame of the same index (reports, time), observer yaw (rad) and the
    observer's field position ``(x, y)`` (m; ``None``: unknown)."""

    index: int
    image: np.ndarray
    frame: Frame
    yaw_rad: float
    xy_m: tuple[float, float] | None = None


def pixel_frames(images: Iterable[np.ndarray], reports: RobotSequence, source: str = "video") -> Iterator[PixelFrame]:
    """The video's frames paired with the report sequence's; ``ValueError`` when the video is longer."""
    for k, image in enumerate(images):
        if k >= len(reports):
            raise ValueError(f"{source}: the reports have {len(reports)} frames, the video more")
        x, y, yaw = (float(v) for v in reports.arrays.observer[k])
        yield PixelFrame(k, image, reports.frame(k), yaw, (x, y))


class PipelineStep:
    """The pipeline as a tracker of :class:`PixelFrame` objects (for :func:`lookalike.loop.run`)."""

    def __init__(self, pipe: RobotPipeline) -> None:
        self.pipe = pipe

    def update(self, frame: PixelFrame) -> PipelineResult:
        """Perceive and identify one frame."""
        return self.pipe.update(frame.image, frame.frame.beacons, frame.frame.time, frame.yaw_rad, frame.xy_m)


def identify_video(pipe: RobotPipeline, frames: Iterable[PixelFrame], output: Path, *,
                   annotate: Callable[[PixelFrame, PipelineResult], None] | None = None,
                   advance: Callable[[], None] | None = None) -> RunStats:
    """Run the pipeline over ``frames``, streaming its rows (:func:`labelled_rows`) to ``output``; ``annotate(frame,
    result)`` sees every frame."""
    with MotWriter(output) as writer:
        def sink(frame: PixelFrame, result: PipelineResult) -> None:
            writer.write_rows(labelled_rows(frame.index, result.detections, result.labels, result.tracks))
            if annotate is not None:
                annotate(frame, result)
            if advance is not None:
                advance()

        with one_blas_thread():
            return run_loop(PipelineStep(pipe), frames, sink)


def identify_robots(run: RobotRun, output: Path, annotate: Path | None = None, fps: float | None = None,
                    advance: Callable[[], None] | None = None) -> Any:
    """Run ``run`` into ``output`` (MOTChallenge rows) and, with ``annotate``, an annotated MP4 at ``fps`` frames/s
    (None: the source's); ``advance`` after each frame. Returns :func:`identify_video`'s statistics; ``ValueError``
    naming the source for frames that do not fit the reports."""
    from lookalike.viz.video import VideoWriter

    writer = VideoWriter(annotate, fps=fps or run.fps) if annotate is not None else None
    n_agents = run.seq.config.n_agents

    def draw(f: Any, result: Any) -> None:
        if writer is not None:
            writer.write(annotate_frame(f.image, result, [
                f"{run.identifier} from pixels, {n_agents} robots",
                f"frame {f.index + 1}  t = {f.frame.time:.2f} s  {len(result.detections)} detection(s)"]))

    try:
        return identify_video(run.pipe, pixel_frames(run.images, run.seq, f"--reports: {run.reports}"), output,
                              annotate=draw, advance=advance)
    except ValueError as exc:
        raise ValueError(f"{run.source}: {exc}") from exc
    finally:
        if writer is not None:
            writer.close()


def run_robots(request: TrackRequest, annotate: Path | None, on_event: Callable[[Event], None]) -> RunResult:
    """``track --video V --pipeline robots --reports R`` (or ``--bag``): robots found, oriented, placed and identified
    by ``request.tracker`` (``sort``: ``set``) into ``request.output`` and, with ``annotate``, an annotated MP4 (told
    as ``request.annotate``); what it does told to ``on_event``. ``ValueError`` or ``TypeError`` for a bad input."""
    from lookalike.pipeline.files import tracker_params

    video, bag, output = request.video_path, request.bag, request.output
    identifier = check_robots(video, request.pipeline or "robots", request.reports, request.tracker, output, bag,
                              request.camera_topic)
    settings = request.settings
    if request.params_file is not None:
        settings = [*(f"{k}={v}" for k, v in tracker_params(request.tracker, [], request.params_file).items()),
                    *settings]
    try:
        run = prepare_robots(video, request.reports, identifier, settings, request.detector_model,
                             request.heading_model, request.min_score, bag=bag, camera_topic=request.camera_topic,
                             heading_topics=request.heading_topics)
    except (ValueError, OSError, TypeError) as exc:
        raise ValueError(f"{'' if bag is None else '--bag: '}{exc}") from exc
    name = f"identifying robots in {run.source.name}"
    on_event(Event("start", name, run.total))
    stats = identify_robots(run, output, annotate, request.fps, advance=lambda: on_event(Event("advance", name, 1)))
    on_event(Event("end", name))
    speed = f"{stats.fps:,.1f}" if stats.seconds > 0 else "inf"
    where = f"{output}" + (f", {request.annotate}" if annotate is not None else "")
    on_event(Event("result", f" from pixels: {stats.frames} frames, {speed} frames/s (detector + heading + "
                             f"identifier) → {where}", name=identifier))
    if dropped(run.pipe):
        on_event(Event("line", f"dropped as implausible: {dropped(run.pipe)}"))
    return RunResult("pipeline", [output], 1)


def dropped(pipe: RobotPipeline) -> str:
    """The detections ``pipe`` dropped as implausible, ``N why`` comma-separated (empty if none)."""
    return ", ".join(f"{n} {why}" for why, n in pipe.dropped.items() if n)


def robot_video(sequence: Path, seed: int = 0) -> tuple[RobotSequence, Iterator[np.ndarray]]:
    """The robot sequence at ``sequence`` and its frames seen through the robot camera (640×480, 70°; ``seed``: the
    lighting, blur and pixel noise)."""
    seq = read_robot_sequence(sequence)
    return seq, (frame.image for frame in render_robot_frames(seq, pixel_camera(), seed))


__all__ = ["PIPELINES", "SIZE_TOLERANCE", "PipelineStep", "PixelFrame", "RobotRun", "check_robots", "dropped",
           "identify_robots", "identify_video", "pixel_frames", "prepare_robots", "robot_video",
           "run_robots"]
