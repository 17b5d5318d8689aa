"""``lookalike record-pixels``: rendered robot sequences through the pixel pipeline, written as labelled
recordings (``.labelled.jsonl``, renderer truth) for ``lookalike train --recordings``."""

from __future__ import annotations

from pathlib import Path

import typer

from lookalike.cli.app import app, check_outputs_or_fail, check_teams, console, fail, failing
from lookalike.sim import preset
from lookalike.sim.presets import TEAM_HELP


@app.command("record-pixels")
def record_pixels(
    output: Path = typer.Option(..., "-o", "--output", help="Folder for the .labelled.jsonl recordings."),
    preset_name: str = typer.Option("m10n7", "--preset", help=f"The team: {TEAM_HELP}."),
    sequences: int = typer.Option(3, "--sequences", min=1, help="Recordings to make."),
    frames: int = typer.Option(300, "--frames", min=1, help="Frames per recording (30 Hz)."),
    seed: int = typer.Option(700_000, "--seed", min=0, help="Base seed (recording k: seed + 1000·preset index + k, as "
                             "`bench pixels`; the shipped detector and heading models train on seeds below 400000)."),
    max_detections: int | None = typer.Option(
        None, "--max-detections", min=1, help="Most probable pixel detections kept per frame, at most the "
        "preset's M (default: M)."),
    detector_model: Path | None = typer.Option(None, "--detector-model", help="HOG cascade (default: shipped)."),
    heading_model: Path | None = typer.Option(None, "--heading-model", help="Heading classifier (default: shipped)."),
    min_iou: float = typer.Option(0.3, "--min-iou", min=0.0, max=1.0, help="IoU for a detection to be a robot."),
) -> None:
    """Render robot sequences, detect them from the pixels and write each as a labelled recording
    (pixel detections, renderer truth as labels, the simulated reports)."""
    check_outputs_or_fail({"-o/--output": output}, [detector_model, heading_model], folders={"-o/--output"})
    from lookalike.bench.pixel_recordings import record_pixels as record
    from lookalike.bench.pixel_recordings import write_recording
    from lookalike.cli.progress import progress_bars
    from lookalike.parallel import one_blas_thread
    from lookalike.sim.robot_camera import pixel_camera
    from lookalike.vision.pipeline import PipelineConfig, RobotPipeline

    check_teams("--preset", [preset_name])
    world = preset(preset_name)
    if max_detections is not None and max_detections > world.max_detections:
        fail(f"--max-detections {max_detections}: a recording of {preset_name} keeps at most its "
             f"M={world.max_detections} detections a frame")
    camera = pixel_camera()
    with failing(ValueError, OSError):
        config = PipelineConfig(n_agents=world.n_agents, max_detections=max_detections or world.max_detections)
        pipe = RobotPipeline.from_files(detector_model, heading_model, camera, config)
        recordings = []
        with progress_bars() as progress, one_blas_thread():
            for rec in record(preset_name, sequences, frames, seed, pipe, camera, min_iou, progress):
                recordings.append(rec)
                console.print(f"wrote {write_recording(rec, output, preset_name)}", markup=False)
    n_det = sum(int(r.arrays.det_valid.sum()) for r in recordings)
    n_fp = sum(int(((r.arrays.det_label < 0) & r.arrays.det_valid).sum()) for r in recordings)
    console.print(f"wrote {len(recordings)} recordings to {output} ({sequences} × {frames} frames, {n_det} pixel "
                  f"detections, {n_fp} false positives; seeds {recordings[0].seed}–{recordings[-1].seed})",
                  markup=False)
