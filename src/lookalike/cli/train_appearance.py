"""``lookalike train-appearance``: train the learned diver appearance model (needs the 'train' extra)."""

from __future__ import annotations

import importlib.util
from pathlib import Path

import typer

from lookalike.cli.app import app, check_outputs_or_fail, console, fail, failing, require


@app.command("train-appearance")
def train_appearance(
    output: Path = typer.Option(..., "-o", "--output", help="Folder for diver_reid.onnx and diver_reid.json."),
    scenarios: int = typer.Option(24, min=1, help="Training scenarios (new divers, seeds 5000+)."),
    frames: int = typer.Option(300, min=10, help="Frames per training scenario."),
    epochs: int = typer.Option(24, min=1, help="Passes over the training crops."),
    minutes: float | None = typer.Option(None, min=0.1, help="Stop after this many minutes."),
    seed: int = typer.Option(0, help="Seed of the run (weights, augmentation, box jitter)."),
    threads: int = typer.Option(1, min=1, help="Torch threads."),
    device: str = typer.Option("cpu", help="Torch device: cpu, cuda or auto."),
) -> None:
    """Train the small CNN embedding on crops of new rendered divers and export it to ONNX.

    The shipped model (lookalike/vision/models_data/diver_reid.onnx) is this command's defaults."""
    require("torch", "onnxruntime")  # (ONNX Runtime measures the exported model's tracker thresholds)
    if not _installed("onnx"):  # torch's ONNX export needs it; it comes with no user extra
        fail("train-appearance: needs the onnx package to export the model; install it: pip install 'onnx>=1.15'")
    from lookalike.learn.appearance_train import AppearanceTrainConfig
    from lookalike.learn.appearance_train import train_appearance as run
    from lookalike.learn.device import torch_device
    with failing(ValueError, prefix="--"):
        torch_device(device)  # before the output folder is made and the crops rendered
    check_outputs_or_fail({"-o/--output": output}, folders={"-o/--output"})
    if output.exists() and not output.is_dir():
        fail(f"-o/--output: {output} is a file; give a folder")
    with failing(ValueError, RuntimeError):
        config = AppearanceTrainConfig(scenarios=scenarios, frames=frames, epochs=epochs, minutes=minutes, seed=seed,
                                       threads=threads, device=device)
        info = run(config, output, log=lambda line: console.print(line, markup=False))
    console.print(f"[green]trained[/] in {info['minutes']:.1f} min: validation AUC {info['validation']['best_auc']:.4f}"
                  f" → {output / info['model']}")


def _installed(module: str) -> bool:
    """Whether ``module`` can be found (without importing it)."""
    try:
        return importlib.util.find_spec(module) is not None
    except ImportError:
        return False
