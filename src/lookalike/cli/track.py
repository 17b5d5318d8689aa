"""``lookalike track``: argument parsing and printing; the run is :func:`lookalike.pipeline.run`."""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

import typer
from rich.markup import escape

from lookalike.cli.app import app, console, fail, failing
from lookalike.pipeline import files
from lookalike.pipeline.request import TrackRequest

__all__ = ["build_tracker", "track"]


def build_tracker(name: str, settings: list[str], params_file: Path | None = None) -> Any:
    """:func:`lookalike.pipeline.files.build_tracker`, failing with a readable message."""
    with failing(ValueError, TypeError):
        return files.build_tracker(name, settings, params_file)


def _run(request: TrackRequest) -> None:
    """:func:`lookalike.pipeline.run`, printed; Ctrl-C: a line saying that the result in progress was not written,
    exit 130; a live run ended by an error: exit 1 after its result line."""
    from lookalike.cli.progress import printed_events
    from lookalike.pipeline import run

    try:
        with failing(ValueError, TypeError), printed_events() as on_event:
            result = run(request, on_event)
    except KeyboardInterrupt:
        console.print("\n[yellow]Interrupted.[/] The result in progress was not written; files finished before are "
                      "kept" + (f" ({escape(str(request.annotate))} is left as it was)."
                                if request.annotate is not None else "."))
        raise SystemExit(130) from None
    if result.failure is not None:
        kind, _, why = result.failure.partition(": ")
        fail(f"the live run stopped on {'a source error' if kind == 'source error' else 'an error'} ({why}); "
             f"{request.output} holds every frame tracked before it", code=1)


@app.command()
def track(
    path: Path | None = typer.Argument(
        None, help="det.txt, a sequence folder, or a folder of sequences (with --video: the det.txt)."
    ),
    output: str = typer.Option(..., "-o", "--output", metavar="PATH",
                               help="Result file (single det.txt or --video) or folder."),
    tracker: str = typer.Option("sort", "--tracker", "-t", help="Registered tracker name (with --pipeline or --bag: "
                                "an identifier, default set)."),
    set_: list[str] | None = typer.Option(
        None, "--set", "-s", help="Tracker parameter KEY=VALUE (repeatable); see `lookalike trackers`."
    ),
    min_score: float = typer.Option(float("-inf"), help="Drop detections with a lower score."),
    video_arg: str | None = typer.Option(
        None, "--video", metavar="<path|0|url>", help="Video file or image folder (img1): appearance features from "
        "its pixels; also writes <output stem>.health.csv and, for merging trackers, <output stem>.merges.csv. Or a "
        "live source: a camera index (0) or a stream URL (rtsp://, http://) with --detector (docs: live camera "
        "how-to)."
    ),
    detections: Path | None = typer.Option(None, "--detections", help="det.txt for --video (or give it as PATH)."),
    annotate: Path | None = typer.Option(
        None, "--annotate", help="With --video: annotated MP4 (uncertain identities dashed with '?', health banner); "
        "with --points: the tracks drawn on --video V, or on white frames."
    ),
    team_size: int | None = typer.Option(None, "--team-size", min=0, help="Known number of targets (health checks)."),
    targets: int | None = typer.Option(None, "--targets", min=0, help="Known number of targets N: a closed set of "
                                       "N identities (the tracker's max_targets; also the health checks' team size); "
                                       "0: an open set (no number inferred from a blob video)."),
    health_window: int = typer.Option(15, "--health-window", min=1, help="Health monitor window in frames."),
    fps: float | None = typer.Option(None, "--fps", min=0.1, help="With --video: frame rate (default: the input's)."),
    features: str = typer.Option("video", "--features", help="With --video: deepsort/diversort features: "
                                 "hand-crafted, standardised on this video ('video') or with the diver calibration "
                                 "('divers'); the shipped learned embedding ('learned'); or an embedding FILE.onnx."),
    detector: str | None = typer.Option(None, "--detector", help="With --video: detect with 'blob' (static camera) "
                                        "or an ONNX model FILE.onnx instead of reading a det.txt."),
    save_detections: Path | None = typer.Option(None, "--save-detections", help="With --detector: also write the "
                                                "boxes found to this MOTChallenge file (track it again with "
                                                "--detections)."),
    blob: list[str] | None = typer.Option(None, "--blob", help="Detector setting KEY=VALUE (repeatable): for 'blob' "
                                          "e.g. threshold=30 polarity=dark min_area_px=80; for FILE.onnx e.g. "
                                          "score=0.4 classes=0 layout=yolo (docs: ONNX detector how-to)."),
    pipeline: str | None = typer.Option(None, "--pipeline", help="With --video: 'robots' finds, orients, places and "
                                        "identifies (-t set|kalman_ha|kalman_ha2|jpda|lstm) robots from the pixels."),
    reports: Path | None = typer.Option(None, "--reports",
                                        help="With --pipeline: heading reports (`simulate` .jsonl)."),
    detector_model: Path | None = typer.Option(None, "--detector-model",
                                               help="With --pipeline: `train-detector` model."),
    heading_model: Path | None = typer.Option(None, "--heading-model", help="With --pipeline: `train-heading` model."),
    params_file: Path | None = typer.Option(None, "--params", help="Parameter file written by `lookalike tune` "
                                            "(for this tracker); --set overrides its values."),
    offline_opt: bool | None = typer.Option(None, "--offline/--online", help="With --targets N: decide the N "
                                            "identities over the whole sequence at once (offline closed set; on a "
                                            "blob video, learning each target's look from the video itself), or "
                                            "frame by frame. Default: offline for --video with --detector blob, "
                                            "online otherwise."),
    points: Path | None = typer.Option(None, "--points", help="Anonymous points as input: a frame,x,y CSV, or "
                                       "MOTChallenge rows frame,id,x,y (tracked as small boxes; --fps, default 25)."),
    no_seqinfo_length: bool = typer.Option(False, "--no-seqinfo-length", help="Track every frame in det.txt even "
                                           "past seqinfo.ini's seqLength (by default a frame past it is an error)."),
    det_format: str = typer.Option("auto", "--det-format", help="The detection file's columns: 'auto' (MOTChallenge, "
                                   "a header line naming the columns, or frame,x1,y1,x2,y2,score[,class] told apart "
                                   "by their values; a note says what was assumed), 'mot', or the column names, e.g. "
                                   "frame,x1,y1,x2,y2,score,class ('frame0' for 0-based frames)."),
    bag: Path | None = typer.Option(None, "--bag", help="A rosbag2 folder as input, through the robots pipeline "
                                    "(sensor_msgs/Image and sensor_msgs/Imu; the 'ros' extra)."),
    camera_topic: str | None = typer.Option(None, "--camera-topic", help="With --bag: the camera's image topic."),
    heading_topics: str | None = typer.Option(None, "--heading-topics", help="With --bag: the robots' Imu topics, "
                                              "comma-separated, robot 0 first (default /robot_0/imu, /robot_1/imu, "
                                              "...)."),
    max_frames: int | None = typer.Option(None, "--max-frames", min=1, help="Live --video: stop after N frames."),
    seconds: float | None = typer.Option(None, "--seconds", min=0.0, help="Live --video: stop after S seconds."),
) -> None:
    """Run a tracker over MOTChallenge detections and write MOTChallenge results (on a video with --video)."""
    request = TrackRequest(Path(output), tracker, path, video_arg, detections, points, bag, detector, blob or [],
                           pipeline, reports, annotate, save_detections, targets, offline_opt,
                           max_frames, seconds, set_ or [], params_file, min_score, fps,
                           features, team_size, health_window, det_format, not no_seqinfo_length, detector_model,
                           heading_model, camera_topic, heading_topics,
                           output_folder=output.endswith(("/", os.sep)))
    try:
        _run(request)
    except OSError as exc:  # an output that cannot be written, an input that cannot be read
        fail(f"{exc.filename or output}: {exc.strerror or exc}")
