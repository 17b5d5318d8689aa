"""Hyper-parameter search for the LSTM associator with Optuna (``hidden``, ``num_layers``, ``learning_rate`` in log
space): each trial a training run scored on the validation seeds; the choice scored again on :data:`CHECK_SEED_BASE`."""

from __future__ import annotations

import dataclasses
import json
import math
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from lookalike._files import write_bytes
from lookalike._optional import needs
from lookalike.learn.checkpoints import changed_settings
from lookalike.parallel import JobPool
from lookalike.sim import RobotWorldConfig
from lookalike.trackers.parts.weights_io import copy_weights

SAMPLERS = ("tpe", "random")
CHECK_SEED_BASE = 1_800_000_000  # held-out seeds that score the chosen network (neither training nor validation)


@dataclass(frozen=True)
class SearchSpace:
    """Ranges searched in log space: units per layer, stacked layers, Adam's initial learning rate."""

    hidden: tuple[int, int] = (16, 256)
    layers: tuple[int, int] = (1, 6)
    learning_rate: tuple[float, float] = (3e-4, 3e-2)

    def __post_init__(self) -> None:
        for name in ("hidden", "layers", "learning_rate"):
            lo, hi = getattr(self, name)
            if not 0 < lo <= hi:
                raise ValueError(f"SearchSpace.{name}: need 0 < low <= high, got ({lo}, {hi})")

    @classmethod
    def parse(cls, text: str) -> SearchSpace:
        """From ``"hidden=16:256,layers=1:6,learning_rate=3e-4:3e-2"`` (omitted names keep their defaults)."""
        ranges: dict[str, Any] = {}
        for part in (p.strip() for p in text.split(",") if p.strip()):
            name, _, span = part.partition("=")
            lo, _, hi = span.partition(":")
            if name not in ("hidden", "layers", "learning_rate") or not hi:
                raise ValueError(f"search space: expected NAME=LOW:HIGH with NAME hidden, layers or learning_rate, "
                                 f"got {part!r}")
            try:
                ranges[name] = (float(lo), float(hi)) if name == "learning_rate" else (int(lo), int(hi))
            except ValueError:
                raise ValueError(f"search space: {part!r} is not a numeric range") from None
        return cls(**ranges)

    def suggest(self, trial: Any) -> dict[str, Any]:
        """The trial's ``hidden``, ``num_layers`` and ``learning_rate`` (all drawn in log space)."""
        return {"hidden": trial.suggest_int("hidden", *self.hidden, log=True),
                "num_layers": trial.suggest_int("num_layers", *self.layers, log=True),
                "learning_rate": trial.suggest_float("learning_rate", *self.learning_rate, log=True)}


@dataclass(frozen=True)
class SearchResult:
    """The outcome of :func:`run_search`: the choice, its validation and check-seed success rates, the files."""

    params: dict[str, Any]
    value: float
    check_success: float
    check_sequences: int
    trials: int
    failed: int
    best_trial: int
    weights_path: Path
    summary_path: Path
    errors: list[str]


def run_trial(config: Any, world: RobotWorldConfig, out_dir: str, threads: int = 1) -> dict[str, Any]:
    """One training run (a picklable job): ``{"value", "step", "steps", "seconds"}``, or ``{"error"}``."""
    with needs("torch"):
        import torch

    from lookalike.learn.sim_data import make_sim_sampler
    from lookalike.learn.training import train

    torch.set_num_threads(threads)
    started = time.process_time()
    try:
        result = train(config, make_sim_sampler(world, config.relative_headings, config.swap_prob), out_dir)
    except (ValueError, RuntimeError) as exc:
        return {"error": f"{type(exc).__name__}: {str(exc)[:200]}"}
    return {"value": result.best_success, "step": result.best_step, "steps": result.steps,
            "seconds": time.process_time() - started}


def check_success(weights_path: Path, world: RobotWorldConfig, sequences: int, length: int) -> float:
    """Per-slot success rate of the network at ``weights_path`` on ``sequences`` check-seed sequences."""
    from lookalike.learn.data import success_rate
    from lookalike.learn.sim_data import make_sim_sampler
    from lookalike.trackers.lstm.checkpoint import load_weights
    from lookalike.trackers.lstm.network import NumpyAssociationNet

    weights = load_weights(weights_path)
    net = NumpyAssociationNet(weights)
    sample = make_sim_sampler(world, weights.spec.relative_headings)
    xs, ys = zip(*(sample(CHECK_SEED_BASE + k, length, None) for k in range(sequences)))
    x, y = np.stack(xs), np.stack(ys)  # (B, T, n_inputs), (B, T, M)
    net.reset(batch=sequences)
    prob = np.stack([net.step(x[:, t]) for t in range(length)], axis=1)  # (B, T, M, N+1)
    correct, total = success_rate(prob, y)
    return correct / max(total, 1)


def _open_study(storage: str, name: str, meta: dict[str, Any]) -> Any:
    with needs("optuna"):
        import optuna
    optuna.logging.set_verbosity(optuna.logging.WARNING)
    study = optuna.create_study(study_name=name, storage=storage, direction="maximize", load_if_exists=True)
    old = study.user_attrs
    for key, value in meta.items():
        if old and old.get(key) != value:
            was = old.get(key)
            changed = (changed_settings(was, value) if isinstance(was, dict) and isinstance(value, dict)
                       else f"{key} {was!r} (now {value!r})")
            raise ValueError(f"{storage}: study {name!r} was run with other settings: {changed}; continue it with "
                             "the same settings or give another --study")
        if not old:
            study.set_user_attr(key, value)
    return study


def _counted(study: Any) -> list[Any]:
    """The trials that count towards ``--search N``: completed, pruned, or failed with an error; not those cut short
    by an interruption (failed without one), which run again."""
    with needs("optuna"):
        from optuna.trial import TrialState

    return [t for t in study.get_trials(deepcopy=False) if t.state in (TrialState.COMPLETE, TrialState.PRUNED)
            or (t.state == TrialState.FAIL and "error" in t.user_attrs)]


def _sampler(name: str, seed: int) -> Any:
    with needs("optuna"):
        import optuna

    if name == "tpe":
        return optuna.samplers.TPESampler(seed=seed, n_startup_trials=5)
    if name == "random":
        return optuna.samplers.RandomSampler(seed=seed)
    raise ValueError(f"sampler: expected one of {', '.join(SAMPLERS)}, got {name!r}")


def run_search(base: Any, world: RobotWorldConfig, out_dir: str | Path, trials: int, *,
               space: SearchSpace | None = None, sampler: str = "tpe", storage: str | None = None,
               study_name: str = "lstm", workers: int = 1, backend: str = "local", address: str | None = None,
               threads: int = 1, check_sequences: int = 8,
               progress: Callable[[int, int, dict[str, Any]], None] | None = None) -> SearchResult:
    """Run ``trials`` trials in all (a continued study only the missing ones) around ``base`` (a ``TrainConfig``);
    write ``out_dir/trial-NNNN``, ``model.npz`` and ``search.json``; ``progress(done, trials, row)`` after each."""
    with needs("optuna"):
        from optuna.trial import TrialState

    if trials < 1:
        raise ValueError(f"trials must be >= 1, got {trials}")
    space = space or SearchSpace()
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    storage = storage or f"sqlite:///{out / 'search.db'}"
    fixed = {k: v for k, v in dataclasses.asdict(base).items() if k not in ("hidden", "num_layers", "learning_rate")}
    meta = {"base": fixed, "space": dataclasses.asdict(space)}
    study = _open_study(storage, study_name, json.loads(json.dumps(meta)))
    for stale in study.get_trials(deepcopy=False, states=(TrialState.RUNNING,)):
        study.tell(stale.number, state=TrialState.FAIL)  # cut short by an interruption: run it again
        study.enqueue_trial(stale.params, skip_if_exists=False)
    done = len(_counted(study))
    study.sampler = _sampler(sampler, base.seed + done)  # a fresh seed per session: no redrawn points
    errors: list[str] = []
    with JobPool(max(1, min(workers, trials - done)), backend, address) as pool:
        while done < trials:
            batch = [study.ask() for _ in range(min(workers, trials - done))]
            drawn = [space.suggest(t) for t in batch]
            jobs = [pool.submit(run_trial, dataclasses.replace(base, **p), world, str(out / f"trial-{t.number:04d}"),
                                threads) for t, p in zip(batch, drawn)]
            for trial, params, job in zip(batch, drawn, jobs):
                row = job.result()
                if "error" in row:
                    errors.append(row["error"])
                    trial.set_user_attr("error", row["error"])
                    study.tell(trial, state=TrialState.FAIL)
                else:
                    for key in ("step", "steps", "seconds"):
                        trial.set_user_attr(key, row[key])
                    study.tell(trial, row["value"])
                done += 1
                if progress is not None:
                    progress(done, trials, {"trial": trial.number, **params, **row, "best": _best(study)})
    complete = study.get_trials(deepcopy=False, states=(TrialState.COMPLETE,))
    if not complete:
        raise ValueError(f"no trial completed ({errors[0] if errors else 'none ran'})")
    best = study.best_trial
    source = out / f"trial-{best.number:04d}" / "model.npz"
    weights = out / "model.npz"
    copy_weights(source, weights)
    check = check_success(weights, world, check_sequences, base.sequence_length)
    chosen = {"hidden": int(best.params["hidden"]), "num_layers": int(best.params["num_layers"]),
              "learning_rate": float(best.params["learning_rate"])}
    summary = {
        "chosen": chosen, "validation_success": float(best.value), "best_trial": best.number,
        "check_success": check, "check_sequences": check_sequences, "check_seed_base": CHECK_SEED_BASE,
        "trials": len(_counted(study)),
        "failed": sum(t.state == TrialState.FAIL for t in _counted(study)),
        "sampler": sampler, "storage": storage, "study": study_name, "space": dataclasses.asdict(space),
        "base": fixed, "weights": str(weights),
        "all_trials": [{"trial": t.number, **t.params, "value": t.value, **t.user_attrs} for t in complete],
    }
    summary_path = out / "search.json"
    write_bytes(summary_path, (json.dumps(summary, indent=2, default=_json_default) + "\n").encode())
    return SearchResult(chosen, float(best.value), check, check_sequences, summary["trials"], summary["failed"],
                        best.number, weights, summary_path, errors)


def _best(study: Any) -> float:
    try:
        return float(study.best_value)
    except ValueError:
        return math.nan


def _json_default(value: Any) -> Any:
    if isinstance(value, np.generic):
        return value.item()
    raise TypeError(f"not JSON: {type(value).__name__}")


__all__ = ["CHECK_SEED_BASE", "SAMPLERS", "SearchResult", "SearchSpace", "check_success", "run_search", "run_trial"]
