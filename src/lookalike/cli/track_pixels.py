"""``lookalike track --video FILE --pipeline robots`` (robot identities from a video's pixels, see
:mod:`lookalike.viz.robot_pixels`) and ``lookalike render-robots``."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import typer
from rich.markup import escape

from lookalike.cli.app import app, check_outputs_or_fail, console, fail, failing
from lookalike.cli.progress import bars
from lookalike.io.robot_sequences import read_robot_sequence
from lookalike.trackers.registry import parse_parameter
from lookalike.vision.pipeline import IDENTIFIERS, PipelineConfig, RobotPipeline
from lookalike.viz.robot_pixels import (
    annotate_frame,
    identifier_settings,
    identify_video,
    pixel_camera,
    pixel_frames,
    render_robot_frames,
)

PIPELINES = ("robots",)
SIZE_TOLERANCE = 2.0  # box height vs a robot's at its ground position; true boxes 0.79-1.48 on m5n3 seeds 11-12


def _check(video: Path | None, pipeline: str, reports: Path | None, identifier: str, output: Path,
           bag: bool = False) -> None:
    if video is None and not bag:
        fail("--pipeline: give the video with --video FILE")
    if pipeline not in PIPELINES:
        fail(f"--pipeline: choose one of {', '.join(PIPELINES)}, got {pipeline!r}")
    if reports is None and not bag:
        fail("--pipeline robots: needs --reports (the heading reports: a `lookalike simulate` .jsonl)")
    if identifier not in IDENTIFIERS:
        fail(f"--tracker: with --pipeline robots choose an identifier: {', '.join(IDENTIFIERS)} (got {identifier!r})")
    if output.is_dir():
        fail(f"-o/--output: {output} is a folder; give a result file such as tracks.txt")


def run_track_pixels(video: Path | None, output: Path, pipeline: str, reports: Path | None, detector_model: Path | None,
                     heading_model: Path | None, identifier: str, settings: list[str], *,
                     annotate: Path | None = None, fps: float | None = None, min_score: float = 0.5,
                     annotate_as: Path | None = None, bag: Path | None = None, camera_topic: str | None = None,
                     heading_topics: str | None = None) -> None:
    """Run pipeline ``pipeline`` over ``video`` with the reports of ``reports`` (or over the rosbag2 folder ``bag``:
    images of ``camera_topic``, headings of the comma-separated ``heading_topics``); write MOTChallenge rows to
    ``output`` and, with ``annotate``, an annotated MP4 (printed as ``annotate_as``). ``min_score``: detector
    probability (-inf: 0.5)."""
    from lookalike.viz.overlay import source_frames
    from lookalike.viz.video import VideoWriter

    identifier = "set" if identifier == "sort" else identifier  # track's default tracks boxes; robots get set
    _check(video, pipeline, reports, identifier, output, bag is not None)
    if bag is not None and camera_topic is None:
        fail("--bag: give --camera-topic (the sensor_msgs/Image topic the pipeline reads)")
    source = video or bag
    assert source is not None
    camera = pixel_camera()
    with failing(ValueError, OSError, TypeError, prefix="" if bag is None else "--bag: "):
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
            images, total, video_fps = bag_images(bag, camera_topic or ""), len(seq), seq.config.frame_rate_hz
        else:
            images, total, video_fps = source_frames(source)
    if total and total > len(seq):
        fail(f"--reports: {reports} has {len(seq)} frames but the video has {total}")
    writer = VideoWriter(annotate, fps=fps or video_fps) if annotate is not None else None

    def draw(f: Any, result: Any) -> None:
        if writer is not None:
            writer.write(annotate_frame(f.image, result, [
                f"{identifier} from pixels, {seq.config.n_agents} robots",
                f"frame {f.index + 1}  t = {f.frame.time:.2f} s  {len(result.detections)} detection(s)"]))

    try:
        with bars("identifying robots") as progress:
            task = progress.add_task(source.name, total=total or None)
            stats = identify_video(pipe, pixel_frames(images, seq, f"--reports: {reports or bag}"), output,
                                   annotate=draw, advance=lambda: progress.advance(task))
    except ValueError as exc:
        fail(f"{source}: {exc}")
    finally:
        if writer is not None:
            writer.close()
    speed = f"{stats.fps:,.1f}" if stats.seconds > 0 else "inf"
    where = escape(f"{output}" + (f", {annotate_as or annotate}" if annotate else ""))
    console.print(f"[green]{identifier}[/] from pixels: {stats.frames} frames, {speed} frames/s (detector + heading + "
                  f"identifier) → {where}")
    dropped = ", ".join(f"{n} {why}" for why, n in pipe.dropped.items() if n)
    if dropped:
        console.print(f"dropped as implausible: {dropped}", markup=False)


@app.command("render-robots")
def render_robots(
    sequence: Path = typer.Argument(..., help="A robot sequence written by `lookalike simulate` (.jsonl)."),
    output: Path = typer.Option(..., "-o", "--output", help="MP4 to write."),
    seed: int = typer.Option(0, help="Seed of the lighting, blur and pixel noise."),
) -> None:
    """Draw a simulated robot sequence through the robot camera (640×480, 70°) as a video: the input of
    `lookalike track --video FILE --pipeline robots --reports SEQUENCE`."""
    from lookalike.viz.video import VideoWriter

    check_outputs_or_fail({"-o/--output": output}, [sequence])
    with failing(ValueError, OSError):
        seq = read_robot_sequence(sequence)
    with bars("rendering") as progress, VideoWriter(output, fps=seq.config.frame_rate_hz) as writer:
        task = progress.add_task("render", total=len(seq))
        for frame in render_robot_frames(seq, pixel_camera(), seed):
            writer.write(frame.image)
            progress.advance(task)
    console.print(f"wrote {output} ({len(seq)} frames)", markup=False)
