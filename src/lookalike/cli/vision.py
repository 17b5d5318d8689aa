"""``lookalike train-detector`` and ``lookalike train-heading``: train the vision models from rendered robots (the
detector also from a folder of ``positives/`` and ``negatives/`` images)."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import numpy as np
import typer
from rich.progress import Progress, TextColumn

from lookalike.cli.app import app, check_outputs_or_fail, console, fail, failing, require
from lookalike.cli.progress import bars
from lookalike.io.outputs import atomic_path
from lookalike.learn.vision_train import train_robot_detector


def _progress() -> Progress:
    return bars("{task.description}", TextColumn("{task.fields[note]}"), transient=False)


@app.command("train-detector")
def train_detector(
    output: Path = typer.Option(..., "-o", "--output", help="Model file to write (.npz)."),
    data: Path | None = typer.Option(None,
                                     help="Folder with positives/ and negatives/ images; default: rendered robots."),
    frames: int = typer.Option(300, help="Rendered frames to train on (without --data)."),
    stages: int = typer.Option(20, help="Cascade stages."),
    negatives: int = typer.Option(2000, help="Hard negatives per stage."),
    copies: int = typer.Option(2, help="Augmented copies per positive (rotation ±15°, scale, flip, cut-outs)."),
    seed: int = typer.Option(0, min=0, help="Seed of rendering, augmentation and boosting."),
    validation_frames: int = typer.Option(100, help="Held-out rendered frames (seed + 1000003) that choose the "
                                          "cascade prefix and pyramid start and calibrate the probability "
                                          "(without --data; 0: keep every stage)."),
) -> None:
    """Train the HOG cascade robot detector and save it."""
    rendered = [name for name, value, default in (("--frames", frames, 300), ("--validation-frames", validation_frames,
                                                                            100)) if value != default]
    if data is not None and rendered:
        fail(f"{', '.join(rendered)}: only without --data (rendered robots; --data trains on its images and keeps "
             "every stage)")
    check_outputs_or_fail({"-o/--output": output}, input_folders=[data])
    require("sklearn")
    with failing(ValueError):
        with _progress() as bar:
            def step(description: str, total: int) -> Callable[[int, str], None]:
                task = bar.add_task(description, total=total, note="")
                return lambda done, note: bar.update(task, completed=done, note=note)

            model, trained, tried = train_robot_detector(data, frames, stages, negatives, copies, seed,
                                                         validation_frames, step)
    with atomic_path(output) as tmp:
        model.save(tmp)
    if tried:
        best = next(t for t in tried if t.stages == len(model.stages)
                    and t.min_height_px == model.config.min_height_px)
        console.print(f"held-out ({validation_frames} frames): kept {len(model.stages)} of {trained} stages, pyramid "
                      f"from {model.config.min_height_px:g} px; precision {best.precision:.3f}, recall "
                      f"{best.recall:.3f}")
    stumps = sum(len(s.index) for s in model.stages)
    console.print(f"wrote {output}: {len(model.stages)} stages, {stumps} stumps", markup=False)


@app.command("train-heading")
def train_heading_command(
    output: Path = typer.Option(..., "-o", "--output", help="Model file to write (.npz)."),
    frames: int = typer.Option(400, help="Rendered training frames (4 robots each)."),
    test_frames: int = typer.Option(100, help="Rendered held-out frames for the reported error (0: none)."),
    folds: int = typer.Option(3, help="Folds of the grid search."),
    seed: int = typer.Option(0, min=0, help="Seed of the training renders; held-out renders use seed + 1000003."),
) -> None:
    """Train the heading classifier on rendered robots, report its held-out error and save it."""
    check_outputs_or_fail({"-o/--output": output})
    require("sklearn")
    from lookalike.learn.vision_train import rendered_heading_samples
    from lookalike.vision.heading import HeadingConfig, mean_abs_error_deg, train_heading

    with failing(ValueError):
        config = HeadingConfig(folds=folds)
        if frames < 1 or test_frames < 0:
            raise ValueError(f"--frames/--test-frames: need frames >= 1, test_frames >= 0, got {frames}, {test_frames}")
        with _progress() as bar:
            task = bar.add_task("rendering", total=frames + test_frames, note="")
            parts = []
            for start in range(0, frames, 20):  # in chunks, for the progress bar; each chunk its own seed
                n = min(20, frames - start)
                parts.append(rendered_heading_samples(n, seed * 7919 + start, config))
                bar.advance(task, n)
            f, h = (np.concatenate(columns) for columns in zip(*parts))
            if len(f) < 2 * folds:
                raise ValueError(f"--frames {frames}: {len(f)} robots rendered; the {folds}-fold grid search needs at "
                                 f"least {2 * folds} (give more --frames or fewer --folds)")
            ft, ht = (rendered_heading_samples(test_frames, seed + 1000003, config) if test_frames
                      else (np.zeros((0, f.shape[1])), np.zeros(0)))
            bar.advance(task, test_frames)
            fit = bar.add_task(f"grid search on {len(f)} robots", total=1, note="")
            model = train_heading(f, h, config, seed=seed, progress=lambda m: bar.update(fit, note=m))
            bar.update(fit, completed=1)
    with atomic_path(output) as tmp:
        model.save(tmp)
    if len(ft):
        err = mean_abs_error_deg(model.estimate(ft).heading_rad, ht)
        console.print(f"held-out mean absolute heading error: {err:.1f} deg on {len(ft)} robots")
    console.print(f"wrote {output} (C={model.c:g}, {len(model.support)} support vectors)", markup=False)
