"""``lookalike bench pixels``: identification from rendered pixels against the simulator's own
detections (:mod:`lookalike.bench.pixels`)."""

from __future__ import annotations

from pathlib import Path

import typer

from lookalike.bench.pixels import DEFAULT_SEED, PERCEPTION_COLUMNS, PIXEL_COLUMNS, pixels_results, pixels_table
from lookalike.cli.app import check_names, check_outputs_or_fail, check_teams, command_line, fail, failing, split_list
from lookalike.cli.bench import SETUPS_HELP, bench_app, print_rows, trained_only, write_csv, write_results
from lookalike.cli.progress import progress_bars
from lookalike.parallel import one_blas_thread
from lookalike.sim.robot_camera import pixel_camera
from lookalike.vision.pipeline import IDENTIFIERS, PipelineConfig, RobotPipeline


@bench_app.command("pixels")
def pixels(
    setups: list[str] = typer.Option(["m3n2", "m5n3"], "--setups", help=SETUPS_HELP),
    identifiers: list[str] = typer.Option(list(IDENTIFIERS), "--trackers", "--identifiers",
                                          help="Identifiers (comma-separated or repeated)."),
    sequences: int = typer.Option(2, "--sequences", min=1, help="Held-out sequences per set-up."),
    frames: int = typer.Option(150, "--frames", min=1, help="Frames per sequence (30 Hz)."),
    seed: int = typer.Option(DEFAULT_SEED, "--seed", min=0, help="Base seed of the held-out sequences."),
    detector_model: Path | None = typer.Option(None, "--detector-model", help="HOG cascade (`lookalike "
                                               "train-detector`); default: the shipped one."),
    heading_model: Path | None = typer.Option(None, "--heading-model", help="Heading classifier (`lookalike "
                                              "train-heading`); default: the shipped one."),
    detect_scale: float = typer.Option(1.0, "--detect-scale", help="Resize frames by this before detection "
                                       "(> 1 finds farther robots, slower)."),
    min_iou: float = typer.Option(0.3, "--min-iou", min=0.0, max=1.0, help="IoU for a detection to be a robot."),
    json_path: Path | None = typer.Option(None, "--json", help="Also write both tables as JSON (results schema)."),
    csv_path: Path | None = typer.Option(None, "--csv", help="Also write the identification rows as CSV."),
    weights: Path | None = typer.Option(None, "--weights", help="Exported weights (.npz) for the lstm rows instead "
                                        "of the shipped ones, e.g. `train --recordings`' model.npz (one set-up)."),
) -> None:
    """Identification success rate from rendered pixels next to the simulator's own detections, per identifier."""
    check_outputs_or_fail({"--json": json_path, "--csv": csv_path}, [detector_model, heading_model, weights])
    setup_list, ident_list = split_list(setups), split_list(identifiers)
    check_teams("--setups", setup_list)
    check_names("--trackers", ident_list, IDENTIFIERS, "identifier")
    if weights is None:
        ident_list = trained_only(ident_list, IDENTIFIERS, setup_list)
    if not setup_list or not ident_list:
        fail("--setups/--trackers: need at least one of each")
    camera = pixel_camera()
    with failing(ValueError, FileNotFoundError):
        pipe = RobotPipeline.from_files(detector_model, heading_model, camera,
                                        PipelineConfig(detect_scale=detect_scale))
        with progress_bars() as progress, one_blas_thread():
            rows, perception = pixels_table(setup_list, ident_list, sequences, frames, seed, pipe, camera, min_iou,
                                            progress, str(weights) if weights else None)
    print_rows(f"Perception on rendered robots, {sequences} × {frames} frames per set-up", perception,
               PERCEPTION_COLUMNS)
    print_rows("Identification success rate: from pixels vs the simulator's detections", rows, PIXEL_COLUMNS)
    options = {"detect_scale": detect_scale, "min_iou": min_iou, "detector_model": detector_model,
               "heading_model": heading_model, **({"weights": weights} if weights else {})}
    write_results(pixels_results(rows, perception, setup_list, sequences, frames, seed, command_line(), options),
                  json_path)
    write_csv(rows, csv_path)
