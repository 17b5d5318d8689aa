"""``lookalike train --recordings DIR``: fine-tune the LSTM associator on labelled recordings (``*.labelled.jsonl``
or rosbag2 folders with labels)."""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from pathlib import Path

from lookalike.cli.app import console, fail, failing, warn
from lookalike.cli.train_options import RunOptions
from lookalike.sim import RobotSequence

PATTERN = "*.labelled.jsonl"


@dataclass(frozen=True)
class RecordingOptions(RunOptions):
    """The ``lookalike train`` options that apply with ``--recordings``."""

    init_from: Path | None
    learning_rate: float | None
    validation_fraction: float
    device: str
    resume: bool
    test: Path | None
    sim_fraction: float = 0.0
    sim_fit: bool = False
    validation: Path | None = None


def recording_paths(folder: Path) -> list[Path]:
    """The recordings of ``folder`` sorted by name: ``*.labelled.jsonl`` files and rosbag2 folders."""
    return sorted([*folder.glob(PATTERN), *(p.parent for p in folder.glob("*/metadata.yaml"))])


def read_recordings(folder: Path, option: str) -> list[RobotSequence]:
    """The recordings (:func:`recording_paths`) of ``folder``; a one-line error naming the folder when it holds
    none, or the recording that cannot be read."""
    from lookalike.io.robot_sequences import read_robot_sequence

    if not folder.is_dir():
        fail(f"{option}: {folder} is not a folder")
    paths = recording_paths(folder)
    if not paths:
        fail(f"{option}: {folder} holds no {PATTERN} (the labelling page's export) and no rosbag2 folder")
    recordings = []
    for path in paths:
        try:
            if path.is_dir():
                from lookalike.io.rosbag import read_labelled_bag

                recordings.append(read_labelled_bag(path))
                continue
            recordings.append(read_robot_sequence(path))
        except (ValueError, OSError) as exc:
            fail(str(exc) if str(path) in str(exc) else f"{path}: {exc}")
    return recordings


def _check_held_out(training: list[Path], folder: Path | None, option: str, against: str = "--recordings") -> None:
    """Fail when ``folder`` holds one of the ``training`` recordings (those of option ``against``): it would score
    the network on what it learnt, or was chosen on."""
    if folder is None or not folder.is_dir():
        return
    shared = {p.resolve() for p in training} & {p.resolve() for p in recording_paths(folder)}
    if shared:
        fail(f"{option}: {folder} holds {len(shared)} of the {against} recordings (e.g. {min(shared).name}); "
             "give a folder of other recordings")


def train_recordings(folder: Path, output: Path, opt: RecordingOptions) -> None:
    """Fine-tune on the recordings of ``folder`` (split by recording, or all of them with ``opt.validation``,
    the folder of the validation recordings), write ``OUTPUT/model.npz``; with ``opt.test``, print the
    starting and fine-tuned success rates on the test recordings."""
    from lookalike.cli.train import _with_progress, torch_device
    from lookalike.learn.recordings import (
        RecordingSampler,
        check_recordings,
        split_recordings,
        validation_arrays,
        without_robots,
    )
    from lookalike.learn.training import TrainConfig, plot_log
    from lookalike.learn.training import train as run_training
    from lookalike.parallel import JobPool
    from lookalike.trackers.lstm.checkpoint import load_weights
    from lookalike.trackers.lstm.weights import shipped_weights_path

    recordings = read_recordings(folder, "--recordings")
    tests = read_recordings(opt.test, "--test") if opt.test is not None else []
    paths = recording_paths(folder)
    _check_held_out(paths, opt.validation, "--validation")
    _check_held_out(paths, opt.test, "--test")
    if opt.validation is not None:  # (the weights are chosen on the validation recordings)
        _check_held_out(recording_paths(opt.validation), opt.test, "--test", "--validation")
    if opt.validation is not None:  # every recording of the folder trains; these validate
        recordings += read_recordings(opt.validation, "--validation")
        paths += recording_paths(opt.validation)
    names = [str(p) for p in paths]
    n, m = recordings[0].config.n_agents, recordings[0].config.max_detections
    device = torch_device(opt.device)
    with failing(ValueError):
        init_path = opt.init_from if opt.init_from is not None else shipped_weights_path(n, m)
        init = load_weights(init_path)
        spec = init.spec
        check_recordings(spec, recordings, names)
        for name in without_robots(recordings, names):
            warn(f"{name}: no detection is labelled as a robot, so it teaches only false positives (an export of "
                 "an unlabelled sequence writes every detection as one)")
        check_recordings(spec, tests, [str(p) for p in recording_paths(opt.test)] if opt.test else [])
        if opt.validation is not None:
            n_train = len(recording_paths(folder))
            train_idx, val_idx = list(range(n_train)), list(range(n_train, len(recordings)))
        else:
            train_idx, val_idx = split_recordings(len(recordings), opt.validation_fraction, opt.seed)
        config = TrainConfig(
            n_agents=spec.n_agents, n_slots=spec.n_slots, relative_headings=spec.relative_headings, cell=init.cell,
            hidden=init.hidden, num_layers=len(init.layers), batch_size=opt.batch_size,
            sequence_length=opt.sequence_length, steps=opt.steps, minutes=opt.minutes, seed=opt.seed,
            learning_rate=0.001 if opt.learning_rate is None else opt.learning_rate, patience=opt.patience,
            init_from=str(init_path), protocol=spec.protocol, noise="recordings",
            validation_every=opt.validate_every)
        world = recordings[0].config
        if opt.sim_fit and opt.sim_fraction <= 0:
            raise ValueError("--mix-sim-fit needs a simulated share (--mix-sim above 0)")
        if opt.sim_fit:
            from lookalike.learn.recording_sensor import fit_sensor

            world = dataclasses.replace(world, sensor=fit_sensor([recordings[i].arrays for i in train_idx],
                                                                 world.sensor, world.observer))
        sampler = RecordingSampler(spec, tuple(recordings[i].arrays for i in train_idx), world, opt.sim_fraction)
        validation = validation_arrays(spec, [recordings[i].arrays for i in val_idx], config.bptt)
        pool = JobPool(opt.workers, opt.backend, opt.address)
    held_out = [paths[i].name for i in val_idx]
    info = {"recordings": {"folder": str(folder), "training": [paths[i].name for i in train_idx],
                           "validation": held_out, "sim_fraction": opt.sim_fraction}}
    if opt.validation is not None:
        info["recordings"]["validation_folder"] = str(opt.validation)
    if opt.sim_fit:
        info["recordings"]["sim_sensor"] = dataclasses.asdict(world.sensor)
        console.print(f"simulated share ({opt.sim_fraction:.0%}) with the detector measured on the training "
                      f"recordings: {_sensor_line(world.sensor)}")
    console.print(f"fine-tuning {init_path} on {len(train_idx)} recordings, validating on {len(val_idx)}: "
                  f"{', '.join(held_out)}")
    result = _with_progress(f"fine-tuning M={m}, N={n}", opt.steps, pool, opt.threads, lambda on_step: run_training(
        config, sampler, output, resume=opt.resume, on_step=on_step, device=device, pool=pool, init=init,
        validation=validation, info=info))
    png = plot_log(result.log_path, output / "training_log.png")
    start = result.history[0]["val_success"] if result.history and result.history[0]["step"] == 0 else float("nan")
    console.print(
        f"validation success rate (per slot, held-out recordings) {100 * start:.1f}% at the start, best "
        f"[bold]{100 * result.best_success:.1f}%[/] at step {result.best_step} of {result.steps}; weights "
        f"{result.weights_path}, log {result.log_path}, plot {png}")
    if tests:
        from lookalike.bench.pixel_recordings import identifier_labels
        from lookalike.eval import identification_success_rate, robot_success_rate

        scores = []
        for weights in (init_path, result.weights_path):
            predicted, truth = identifier_labels(tests, "lstm", weights=str(weights))
            scores.append((identification_success_rate(predicted, truth), robot_success_rate(predicted, truth)))
        count = sum(len(t) for t in truth)
        robots = sum(int((t >= 0).sum()) for t in truth)
        (before, before_robots), (after, after_robots) = scores
        console.print(f"test recordings ({len(tests)}, {count} detections): LSTM identification success rate "
                      f"{100 * before:.1f}% with {init_path.name}, [bold]{100 * after:.1f}%[/] fine-tuned; on the "
                      f"{robots} detections of true robots {100 * before_robots:.1f}% and "
                      f"[bold]{100 * after_robots:.1f}%[/]")


def _sensor_line(s: object) -> str:
    """The fitted detector in one line (false positives, detection probability, noise, scores)."""
    from lookalike.sim.robots_config import SensorConfig

    assert isinstance(s, SensorConfig)
    return (f"{s.fp_per_frame:.2f} false positives/frame, p_detect {s.p_detect:.2f} (near {s.p_detect_near:.2f}, "
            f"far {s.p_detect_far:.2f}), position std x {s.std_x0_m:.2f} + {s.std_x_per_m:.3f}/m, y {s.std_y0_m:.2f} + "
            f"{s.std_y_per_m:.3f}/m, heading noise {math.degrees(s.heading_noise_rad):.1f} deg, flips "
            f"{s.heading_flip_prob:.1%}, score Beta {s.tp_score_beta[0]:.1f}, {s.tp_score_beta[1]:.1f} (true), "
            f"{s.fp_score_beta[0]:.1f}, {s.fp_score_beta[1]:.1f} (false)")
