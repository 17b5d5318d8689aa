"""``lookalike train``: train the LSTM associator on the robot simulator (needs the 'train' extra)."""

from __future__ import annotations

import math
import shutil
from pathlib import Path
from typing import Optional

import typer
from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn

from lookalike.cli.app import app, console, fail
from lookalike.sim import PRESET_NAMES, preset


@app.command()
def train(
    preset_name: str = typer.Option("m3n2", "--preset", help=f"Robot world set-up: {', '.join(PRESET_NAMES)}."),
    output: Path = typer.Option(..., "-o", "--output", help="Folder for model.npz/.json, log and checkpoint."),
    steps: int = typer.Option(3000, help="Maximum optimisation steps (batches of sequences)."),
    minutes: Optional[float] = typer.Option(None, help="Stop after this many minutes."),
    cell: str = typer.Option("lstm", help="Recurrent cell: lstm or gru (the paper's comparison)."),
    batch_size: int = typer.Option(16, help="Sequences per batch."),
    sequence_length: int = typer.Option(600, help="Frames per training sequence (multiple of 150)."),
    hidden: int = typer.Option(64, help="Units per recurrent layer."),
    layers: int = typer.Option(5, help="Stacked recurrent layers."),
    seed: int = typer.Option(0, help="Seed of the run (weights and data)."),
    relative: bool = typer.Option(True, help="Add slot-minus-agent heading differences to the input (ours)."),
    threads: int = typer.Option(1, help="Torch threads."),
    resume: bool = typer.Option(False, help="Continue from OUTPUT/checkpoint.pt."),
    ship: bool = typer.Option(False, help="Copy the best weights into the package's shipped weights."),
) -> None:
    """Train the association network on simulated sequences generated on the fly."""
    try:
        import torch
    except ImportError:
        fail("training needs PyTorch: pip install 'lookalike[train]' (torch==2.13.0)")
    from lookalike.learn.sim_data import make_sim_sampler
    from lookalike.learn.training import TrainConfig, plot_log
    from lookalike.learn.training import train as run_training
    from lookalike.learn.weights import WEIGHTS_DIR

    try:
        world = preset(preset_name)
        config = TrainConfig(
            n_agents=world.n_agents, n_slots=world.max_detections, relative_headings=relative, cell=cell, hidden=hidden, num_layers=layers,
            batch_size=batch_size, sequence_length=sequence_length, steps=steps, minutes=minutes, seed=seed,
        )
    except ValueError as exc:
        fail(str(exc))
    torch.set_num_threads(threads)
    columns = (TextColumn("{task.description}"), BarColumn(), MofNCompleteColumn(), TimeElapsedColumn(),
               TextColumn("loss {task.fields[loss]:.3f}  validation {task.fields[val]}"))
    with Progress(*columns, console=console) as progress:
        task = progress.add_task(f"training {preset_name}", total=steps, loss=math.nan, val="–")

        def on_step(row: dict) -> None:
            val = row["val_success"]
            fields = {"loss": row["loss"]}
            if not math.isnan(val):
                fields["val"] = f"{100 * val:.1f}%"
            progress.update(task, completed=row["step"], **fields)

        try:
            result = run_training(config, make_sim_sampler(world, relative), output, resume=resume, on_step=on_step)
        except ValueError as exc:
            fail(str(exc))
    png = plot_log(result.log_path, output / "training_log.png")
    console.print(
        f"best validation success rate [bold]{100 * result.best_success:.1f}%[/] at step {result.best_step} "
        f"of {result.steps}; weights {result.weights_path}, log {result.log_path}, plot {png}"
    )
    if ship:
        WEIGHTS_DIR.mkdir(exist_ok=True)
        target = WEIGHTS_DIR / f"lstm_m{world.max_detections}_n{world.n_agents}"
        shutil.copy(result.weights_path, target.with_suffix(".npz"))
        shutil.copy(result.weights_path.with_suffix(".json"), target.with_suffix(".json"))
        console.print(f"shipped as {target.with_suffix('.npz')}")
