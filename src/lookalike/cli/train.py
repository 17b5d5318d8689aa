"""``lookalike train``: train the LSTM associator (or, with ``--model set``, the set associator for every
team size) on the robot simulator (needs the 'train' extra)."""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING, Any

import typer
from rich.progress import TextColumn

from lookalike._optional import needs
from lookalike.cli.app import app, check_outputs_or_fail, check_study_or_fail, console, fail, failing, require, warn
from lookalike.cli.progress import bars

if TYPE_CHECKING:
    from lookalike.parallel import JobPool
from lookalike.sim import preset
from lookalike.sim.presets import TEAM_HELP

SPACE = "hidden=16:256,layers=1:6,learning_rate=3e-4:3e-2"  # --search's default ranges


@app.command()
def train(
    preset_name: str = typer.Option("m3n2", "--preset", help=f"The team an LSTM is trained for: {TEAM_HELP}."),
    output: Path = typer.Option(..., "-o", "--output", help="Folder for model.npz/.json, log and checkpoint (one "
                                "that holds an earlier run's is refused unless --resume continues it)."),
    steps: int = typer.Option(3000, help="Maximum optimisation steps (batches of sequences)."),
    minutes: float | None = typer.Option(None, help="Stop after this many minutes."),
    cell: str = typer.Option("lstm", help="Recurrent cell: lstm or gru (the paper's comparison)."),
    batch_size: int = typer.Option(16, min=1, help="Sequences per batch."),
    sequence_length: int = typer.Option(600, help="Frames per training sequence (multiple of 150)."),
    hidden: int = typer.Option(64, help="Units per recurrent layer."),
    layers: int = typer.Option(5, help="Stacked recurrent layers."),
    seed: int = typer.Option(0, help="Seed of the run (weights and data)."),
    relative: bool = typer.Option(True, help="Add slot-minus-agent heading differences to the input (ours)."),
    patience: int = typer.Option(12, min=1,
                                 help="Stop after this many validations (every 50 steps) without a new best."),
    threads: int = typer.Option(1, min=1, help="Torch threads."),
    learning_rate: float | None = typer.Option(
        None, help="Adam's initial learning rate (default: the paper's 0.004 for lstm, 0.003 for set; with "
        "--model set --resume, a lower one cools the run down)."),
    swap_prob: float = typer.Option(
        0.0, help="Fraction of training sequences in which two robots swap identities for 1-10 s (ours; "
        "teaches fast re-identification)."),
    init_from: Path | None = typer.Option(
        None, "--init-from",
        help="Start from these exported weights (.npz), e.g. the shipped ones, instead of random."),
    init_transfer: bool = typer.Option(
        False, "--init-transfer", help="With --init-from: the weights may be of another set-up (N, M) of the same "
        "protocol; their input columns and output rows are mapped robot by robot and slot by slot (repeats get "
        "small noise), the recurrent layers copied, the normalisation measured on this preset's data; "
        "--hidden/--layers follow the weights."),
    device: str = typer.Option("cpu", help="Torch device for the network: cpu, cuda or auto."),
    workers: int = typer.Option(1, min=1, help="Processes (or Ray CPUs) generating batches ahead."),
    backend: str = typer.Option("local", help="Batch generation: local (processes) or ray."),
    address: str | None = typer.Option(None, help="Ray cluster address (default: a local ray.init())."),
    resume: bool = typer.Option(False, help="Continue from OUTPUT/checkpoint.pt, made with the same settings (with "
                                "--model set, --steps, --minutes, --patience and --learning-rate may change)."),
    ship: bool = typer.Option(False, help="Copy the best weights into the package's shipped weights."),
    protocol: str = typer.Option(
        "ours", help="Input layout: ours, or paper (the robot-identification paper's N + 4M inputs, no ages, no "
        "relative headings, "
        "no augmentation beyond slot shuffling; shipped as lstm_paper_*)."),
    noise: str = typer.Option("ours", help="Simulator noise model of the training sequences: ours, paper or mix "
                              "(each sequence draws one from its seed)."),
    model: str = typer.Option(
        "lstm", "--model", help="lstm (one network per --preset), or set: one set associator for every team size "
        "(N 1-12, M up to 2N+3, drawn per batch; shipped as set_any; --preset, --cell, --hidden, --layers, "
        "--relative, --protocol, --noise, --swap-prob, --init-from, --sequence-length and --validate-every "
        "do not apply and are refused)."),
    recordings: Path | None = typer.Option(
        None, "--recordings", help="Fine-tune on the labelled recordings (*.labelled.jsonl, the labelling page's "
        "export) of this folder instead of simulated sequences: N and M from the recordings, the network from "
        "--init-from (default: the shipped weights for N, M), a validation split by recording, early stopping; "
        "learning rate 0.001 unless given."),
    mix_sim: float = typer.Option(
        0.0, "--mix-sim", min=0.0, max=1.0, help="With --recordings: share of the training sequences simulated "
        "in the recordings' own world (their header's set-up) instead of cut from the recordings."),
    mix_sim_fit: bool = typer.Option(
        False, "--mix-sim-fit", help="With --mix-sim: simulate that share with the detector measured on the "
        "training recordings (false positives, detection probability, scores, position and heading noise) "
        "instead of the header's."),
    validation_fraction: float = typer.Option(
        0.25, "--validation-fraction", help="With --recordings: share of the recordings held out for validation."),
    validation_folder: Path | None = typer.Option(
        None, "--validation", help="With --recordings: validate on the recordings of this folder instead of a "
        "share of --recordings (which then all train), e.g. to compare runs on the same validation recordings."),
    validate_every: int = typer.Option(50, "--validate-every", min=1, help="Steps between validations."),
    test: Path | None = typer.Option(
        None, "--test", help="With --recordings: after training, score the starting and the fine-tuned weights "
        "(LSTM identification success rate) on the recordings of this folder."),
    search: int | None = typer.Option(
        None, "--search", min=1, help="Hyper-parameter search instead of one run: this many trials (in all, "
        "a resumed study included) over hidden size, depth and learning rate in log space (--space), each a training "
        "run of --steps/--minutes validated on held-out simulator seeds; trials run --workers at a time."),
    sampler: str = typer.Option("tpe", "--sampler", help="With --search: tpe or random."),
    space: str = typer.Option(SPACE, "--space",
                              help="With --search: the ranges searched (log space)."),
    study: str | None = typer.Option(
        None, "--study", help="With --search: Optuna storage URL (default sqlite:///OUTPUT/search.db); an "
        "existing study there is continued."),
) -> None:
    """Train the association network on simulated sequences generated on the fly (or fine-tune it on labelled
    recordings with --recordings, or search its hyper-parameters with --search)."""
    if steps < 1:
        fail(f"--steps: at least 1 optimisation step, got {steps}")
    if minutes is not None and not minutes > 0:
        fail(f"--minutes: a time limit > 0, got {minutes:g}")
    from lookalike.io.outputs import sqlite_file

    require("torch")
    device_given, device = device, torch_device(device)  # every option checked before the output folder is made
    if protocol not in ("ours", "paper"):
        fail(f"--protocol: unknown protocol {protocol!r}; known: ours, paper")
    if model not in ("lstm", "set"):
        fail(f"--model: unknown model {model!r}; known: lstm, set")
    if recordings is not None and search is not None:
        fail("--recordings and --search: choose one")
    _refuse_unused(recordings is not None, search is not None, model, {
        "--model": model != "lstm", "--preset": preset_name != "m3n2", "--cell": cell != "lstm",
        "--hidden": hidden != 64, "--layers": layers != 5, "--no-relative": not relative,
        "--protocol": protocol != "ours", "--noise": noise != "ours", "--swap-prob": swap_prob != 0.0,
        "--init-from": init_from is not None, "--init-transfer": init_transfer, "--ship": ship, "--resume": resume,
        "--learning-rate": learning_rate is not None, "--device": device_given != "cpu",
        "--sequence-length": sequence_length != 600, "--validate-every": validate_every != 50})
    _refuse_misplaced(recordings is not None, search is not None, {
        "--mix-sim": mix_sim != 0.0, "--mix-sim-fit": mix_sim_fit, "--validation-fraction": validation_fraction != 0.25,
        "--validation": validation_folder is not None, "--test": test is not None, "--sampler": sampler != "tpe",
        "--space": space != SPACE, "--study": study is not None})
    check_outputs_or_fail({"-o/--output": output, "--study": sqlite_file(study)},
                          [recordings, init_from, validation_folder], folders={"-o/--output"})
    if search is not None:
        check_study_or_fail(study)
    _check_earlier_run(output, None if search is not None else
                       "set.npz" if model == "set" and recordings is None else "model.npz", resume)
    run: dict[str, Any] = dict(  # the options every training run shares (cli.train_options.RunOptions)
        steps=steps, minutes=minutes, batch_size=batch_size, sequence_length=sequence_length, seed=seed,
        patience=patience, validate_every=validate_every, threads=threads, workers=workers, backend=backend,
        address=address)
    if recordings is not None:
        from lookalike.cli.train_recordings import RecordingOptions, train_recordings

        train_recordings(recordings, output, RecordingOptions(
            **run, init_from=init_from, learning_rate=learning_rate, validation_fraction=validation_fraction,
            device=device, resume=resume, test=test, sim_fraction=mix_sim, sim_fit=mix_sim_fit,
            validation=validation_folder))
        return
    if search is not None:
        from lookalike.cli.train_search import SearchOptions, train_search

        train_search(search, output, preset_name, SearchOptions(
            **run, cell=cell, relative=relative, sampler=sampler, study=study, space=space))
        return
    if model == "set":
        _train_set(output, steps, minutes, batch_size, seed, patience, threads, device, workers, backend, address,
                   resume, ship, learning_rate)
        return
    if learning_rate is None:
        learning_rate = 0.004
    from lookalike.learn.paper_protocol import noise_worlds
    from lookalike.learn.training import TrainConfig
    from lookalike.learn.training import train as run_training
    from lookalike.parallel import JobPool
    from lookalike.trackers.lstm.encoding import EncodingSpec
    from lookalike.trackers.lstm.weights import WEIGHTS_DIR

    if protocol == "paper" and (relative or swap_prob > 0):
        relative, swap_prob = False, 0.0  # the paper's inputs; no augmentation beyond slot shuffling
    with failing(ValueError):
        world = preset(preset_name)
        worlds = noise_worlds(preset_name, noise)
        config = TrainConfig(
            n_agents=world.n_agents, n_slots=world.max_detections, relative_headings=relative, cell=cell,
            hidden=hidden, num_layers=layers, batch_size=batch_size, sequence_length=sequence_length, steps=steps,
            minutes=minutes, seed=seed, learning_rate=learning_rate, patience=patience, swap_prob=swap_prob,
            init_from=str(init_from) if init_from else None, protocol=protocol, noise=noise,
            validation_every=validate_every,
        )
        spec = EncodingSpec(world.n_agents, world.max_detections, relative_headings=relative, protocol=protocol)
        sample, validation = _sim_samplers(world, worlds, spec, noise, swap_prob)
        init = _initial_weights(init_from, init_transfer, spec, validation, sequence_length, seed)
        if init_transfer and init is not None:
            config = dataclasses.replace(config, hidden=init.hidden, num_layers=len(init.layers))
        pool = JobPool(workers, backend, address)
    result = _with_progress(f"training {preset_name}", steps, pool, threads, lambda on_step: run_training(
        config, sample, output, resume=resume, on_step=on_step, device=device, pool=pool, init=init,
        validation_sample=validation,
        info={"transferred_from": init.info["transferred_from"]} if init is not None and init_transfer else None))
    stem = "lstm_paper" if protocol == "paper" else "lstm"
    _finish(result, output, WEIGHTS_DIR / f"{stem}_m{world.max_detections}_n{world.n_agents}.npz" if ship else None)


_UNUSED = {  # the options each kind of run does not read, and why
    "--recordings": (("--model", "--preset", "--cell", "--hidden", "--layers", "--no-relative", "--protocol",
                      "--noise", "--swap-prob", "--init-transfer", "--ship"),
                     "the network is --init-from's, else the shipped one for the recordings' N and M"),
    "--search": (("--model", "--init-from", "--init-transfer", "--ship", "--resume", "--learning-rate", "--hidden",
                  "--layers", "--protocol", "--noise", "--swap-prob", "--device"),
                 "each trial trains a new LSTM on the CPU with the size and learning rate it draws; a study "
                 "continues by itself"),
    "--model set": (("--preset", "--cell", "--hidden", "--layers", "--no-relative", "--protocol", "--noise",
                     "--swap-prob", "--init-from", "--init-transfer", "--sequence-length", "--validate-every"),
                    "the set associator has its own sizes, data and schedule"),
}


def _refuse_unused(recordings: bool, search: bool, model: str, given: dict[str, bool]) -> None:
    """Fail (before any work) when an option that ``given`` marks as set does not apply to this kind of run, or
    lacks the option it needs."""
    if given.get("--init-transfer") and not given.get("--init-from"):
        fail("--init-transfer needs --init-from")
    mode = "--recordings" if recordings else "--search" if search else "--model set" if model == "set" else None
    if mode is None:
        return
    names, why = _UNUSED[mode]
    unused = [name for name in names if given.get(name)]
    if unused:
        fail(f"{', '.join(unused)}: not with {mode} ({why})")


_ONLY_WITH = {  # the options of one kind of run, and what that run is
    "--recordings": (("--mix-sim", "--mix-sim-fit", "--validation-fraction", "--validation", "--test"),
                     "fine-tuning on labelled recordings"),
    "--search": (("--sampler", "--space", "--study"), "the hyper-parameter search"),
}


def _refuse_misplaced(recordings: bool, search: bool, given: dict[str, bool]) -> None:
    """Fail (before any work) when an option of ``--recordings`` or ``--search`` runs is set without it."""
    for mode, on in (("--recordings", recordings), ("--search", search)):
        names, what = _ONLY_WITH[mode]
        misplaced = [name for name in names if given.get(name)]
        if misplaced and not on:
            fail(f"{', '.join(misplaced)}: only with {mode} ({what})")


def _check_earlier_run(output: Path, weights: str | None, resume: bool) -> None:
    """Without ``resume``, fail when ``output`` holds an earlier run's checkpoint or ``weights``, which a new run would
    replace; with it, warn when there is no checkpoint to continue (``weights`` None: a search, which continues
    its study by itself)."""
    if weights is None:
        return
    if resume:
        if not (output / "checkpoint.pt").is_file():
            warn(f"--resume: {output} holds no checkpoint.pt to continue; starting a new run")
        return
    earlier = [name for name in ("checkpoint.pt", weights) if (output / name).exists()]
    if earlier:
        fail(f"-o/--output {output}: holds an earlier run ({', '.join(earlier)}); --resume continues it, or remove "
             "them or give another folder to start over (nothing was written)")


def _sim_samplers(world: Any, worlds: Any, spec: Any, noise: str, swap_prob: float) -> tuple[Any, Any]:
    """Training and validation samplers: ``world`` alone for our protocol on ``ours`` noise; on other noise,
    each sequence from one of ``worlds`` with swaps in training; for the paper's protocol, its encoding, no swaps."""
    from lookalike.learn.paper_protocol import NoiseMixSampler
    from lookalike.learn.sim_data import WorldMixSampler, make_sim_sampler

    relative = spec.relative_headings
    if spec.protocol != "ours":
        return NoiseMixSampler(worlds, spec), NoiseMixSampler(worlds, spec)
    if noise == "ours":
        return make_sim_sampler(world, relative, swap_prob), make_sim_sampler(world, relative)
    return (WorldMixSampler(tuple(make_sim_sampler(w, relative, swap_prob) for w in worlds)),
            WorldMixSampler(tuple(make_sim_sampler(w, relative) for w in worlds)))


def _initial_weights(init_from: Path | None, transfer: bool, spec: Any, sample: Any, length: int,
                     seed: int) -> Any:
    """The weights ``--init-from`` names (None without it); with ``--init-transfer`` mapped onto ``spec``'s
    set-up and normalised on 8 sequences of ``sample`` (seeds just below the training seeds)."""
    from lookalike.learn.training import TRAIN_SEED_BASE
    from lookalike.learn.transfer import transfer_from_file
    from lookalike.trackers.lstm.checkpoint import load_weights

    if transfer and init_from is None:
        raise ValueError("--init-transfer needs --init-from")
    if init_from is None:
        return None
    if transfer:
        return transfer_from_file(str(init_from), spec, sample, [TRAIN_SEED_BASE - 1 - i for i in range(8)],
                                  length, seed)
    return load_weights(init_from, spec.n_agents, spec.n_slots)


def _train_set(output: Path, steps: int, minutes: float | None, batch_size: int, seed: int, patience: int,
               threads: int, device: str, workers: int, backend: str, address: str | None, resume: bool,
               ship: bool, learning_rate: float | None) -> None:
    """``lookalike train --model set``: the set associator over every team size."""
    from lookalike.learn.set_training import SetTrainConfig, train_set
    from lookalike.parallel import JobPool
    from lookalike.trackers.set.network import SHIPPED_SET_WEIGHTS

    device = torch_device(device)
    with failing(ValueError):
        config = SetTrainConfig(steps=steps, minutes=minutes, batch_size=batch_size, seed=seed, patience=patience)
        if learning_rate is not None:
            config = dataclasses.replace(config, learning_rate=learning_rate)
        pool = JobPool(workers, backend, address)
    result = _with_progress("training set (N 1-12)", steps, pool, threads, lambda on_step: train_set(
        config, output, resume=resume, on_step=on_step, device=device, pool=pool))
    _finish(result, output, SHIPPED_SET_WEIGHTS if ship else None, " (mean over the validation teams)")


def _finish(result: Any, output: Path, ship_to: Path | None, detail: str = "") -> None:
    """Plot the training log, print the best validation and, with ``ship_to`` (an ``.npz``), ship the weights."""
    from lookalike.learn.training import plot_log
    from lookalike.trackers.parts.weights_io import copy_weights

    png = plot_log(result.log_path, output / "training_log.png")
    console.print(f"best validation success rate [bold]{100 * result.best_success:.1f}%[/]{detail} at step "
                  f"{result.best_step} of {result.steps}; weights {result.weights_path}, log {result.log_path}, "
                  f"plot {png}")
    if ship_to is not None:
        try:
            ship_to.parent.mkdir(exist_ok=True)
            copy_weights(result.weights_path, ship_to)
        except OSError as exc:
            fail(f"--ship: cannot write {ship_to} ({exc.strerror or exc}); the trained weights are "
                 f"{result.weights_path}")
        console.print(f"shipped as {ship_to}", markup=False)


def torch_device(device: str) -> str:
    """``--device`` resolved (``auto``: cuda where PyTorch sees one), failing in one line on a device PyTorch cannot
    use."""
    from lookalike.learn.device import torch_device as resolve

    try:
        return str(resolve(device))
    except ValueError as exc:
        fail(f"--{exc}")


def _with_progress(description: str, steps: int, pool: JobPool, threads: int,
                   train: Callable[[Callable[[dict], None]], Any]) -> Any:
    """Run ``train(on_step)`` with ``threads`` torch threads inside ``pool`` under a progress bar of ``steps`` showing
    the loss and the validation success rate; a ``ValueError`` becomes a one-line error."""
    with needs("torch"):
        import torch

    torch.set_num_threads(threads)
    with bars("{task.description}", TextColumn("loss {task.fields[loss]:.3f}  validation {task.fields[val]}"),
              transient=False) as progress:
        task = progress.add_task(description, total=steps, loss=math.nan, val="–")

        def on_step(row: dict) -> None:
            fields = {"loss": row["loss"]}
            if not math.isnan(row["val_success"]):
                fields["val"] = f"{100 * row['val_success']:.1f}%"
            progress.update(task, completed=row["step"], **fields)

        with failing(ValueError), pool:
            return train(on_step)
