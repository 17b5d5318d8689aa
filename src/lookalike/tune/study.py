"""An Optuna study choosing a tracker's parameters on labelled sequences: each trial (the first: the defaults) runs the
tracker on every sequence and is valued by :func:`lookalike.tune.objective.objective`."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

from lookalike._optional import needs
from lookalike.parallel import JobPool
from lookalike.trackers.registry import tracker_parameters
from lookalike.tune.data import score_params, sequence_key
from lookalike.tune.objective import Evaluator, criterion, evaluate_job, objective
from lookalike.tune.space import Space, default_space, searched, space_to_json, suggest, trial_values

SAMPLERS = ("tpe", "random")


@dataclass(frozen=True)
class StudyResult:
    """The outcome of :func:`run_study`: the best trial's ``params`` and ``value`` on the sequences ``chosen_on``,
    finished ``trials`` (``failed`` of them), and ``default_value``, the defaults' objective if it completed."""

    params: dict[str, Any]
    value: float
    trials: int
    study_name: str
    chosen_on: list[str]
    criterion: str
    default_value: float | None = None
    failed: int = 0
    errors: list[str] = field(default_factory=list)


def make_sampler(name: str, seed: int) -> Any:
    """An Optuna sampler: ``"tpe"`` (Tree-structured Parzen Estimator) or ``"random"``."""
    with needs("optuna"):
        import optuna

    if name == "tpe":
        return optuna.samplers.TPESampler(seed=seed)
    if name == "random":
        return optuna.samplers.RandomSampler(seed=seed)
    raise ValueError(f"sampler: expected one of {', '.join(SAMPLERS)}, got {name!r}")


def _import_optuna() -> Any:
    with needs("optuna"):
        import optuna
    optuna.logging.set_verbosity(optuna.logging.WARNING)
    return optuna


def _open_study(optuna: Any, name: str, storage: str | None, resume: bool, meta: dict[str, Any]) -> Any:
    if storage is not None and not resume:
        try:
            optuna.load_study(study_name=name, storage=storage)
        except KeyError:
            pass
        else:
            raise ValueError(f"study {name!r} already exists in {storage}; pass --resume to continue it "
                             "or --study-name for a new one")
    study = optuna.create_study(study_name=name, storage=storage, direction="maximize", load_if_exists=resume)
    old = study.user_attrs
    if old:
        for key, value in meta.items():
            if old.get(key) != value:
                raise ValueError(f"study {name!r} was run with another {key} ({old.get(key)!r}); "
                                 "resume it with the same settings or start a new study")
    else:
        for key, value in meta.items():
            study.set_user_attr(key, value)
    return study


def _defaults_in_space(tracker: str, space: Space) -> dict[str, Any]:
    """Trial values of the tracker's defaults, where they lie inside the searched ranges."""
    defaults = {p.name: p.default for p in tracker_parameters(tracker)}
    out: dict[str, Any] = {}
    for name, dim in searched(space).items():
        value = defaults.get(name)
        if value is None:
            if dim.optional:
                out[name] = None
            continue
        if dim.kind == "choice":
            if value in dim.choices:
                out[name] = value
        elif dim.low is not None and dim.high is not None and dim.low <= value <= dim.high:
            out[name] = value
    return trial_values(out, space)


def run_study(tracker: str, sequences: Sequence[Any], *, space: Space | None = None, trials: int = 50,
              sampler: str = "tpe", seed: int = 0, metric: str = "hota+idf1+mota",
              groups: Sequence[str] | None = None, keys: Sequence[str] | None = None,
              storage: str | None = None, study_name: str | None = None, resume: bool = False,
              workers: int = 1, backend: str = "local", address: str | None = None,
              evaluator: Evaluator = score_params,
              progress: Callable[[int, int, float | None], None] | None = None) -> StudyResult:
    """Choose ``tracker``'s parameters on labelled ``sequences`` in ``trials`` trials in all (``sampler`` ``"tpe"`` or
    ``"random"``, seeded by ``seed``; criterion ``metric``), the objective averaged over ``groups`` (default: datasets).
    ``storage``: an Optuna URL (None: in memory) where ``resume`` continues the study of the same settings;
    ``evaluator(tracker, params, sequence)`` gives scores; ``progress(done, trials, best so far)`` after each trial."""
    optuna = _import_optuna()
    crit = criterion(metric)
    if trials < 1:
        raise ValueError(f"trials must be >= 1, got {trials}")
    if not sequences:
        raise ValueError("no sequence to tune on")
    space = default_space(tracker) if space is None else space
    keys = [sequence_key(s) for s in sequences] if keys is None else list(keys)
    groups = [str(getattr(s, "dataset", "")) for s in sequences] if groups is None else list(groups)
    name = study_name or tracker
    meta = {"tracker": tracker, "metric": metric.lower(), "sequences": keys, "space": space_to_json(space)}
    study = _open_study(optuna, name, storage, resume, meta)
    with needs("optuna"):
        from optuna.trial import TrialState

    for stale in study.get_trials(deepcopy=False, states=(TrialState.RUNNING, TrialState.WAITING)):
        if stale.state == TrialState.RUNNING:
            study.tell(stale.number, state=TrialState.FAIL)  # cut short by an interruption: run again
    finished = (TrialState.COMPLETE, TrialState.FAIL, TrialState.PRUNED)
    done = len(study.get_trials(deepcopy=False, states=finished))
    # a fresh sampler seed per session: a resumed random search does not redraw the same points
    study.sampler = make_sampler(sampler, seed + done)
    if done == 0:
        study.enqueue_trial(_defaults_in_space(tracker, space), skip_if_exists=True)
    errors: list[str] = []
    with JobPool(max(1, min(workers, (trials - done) * len(sequences) or 1)), backend, address) as pool:
        shared = [pool.share(s) for s in sequences]
        while done < trials:
            batch = [study.ask() for _ in range(min(workers, trials - done))]
            drawn = [suggest(t, space) for t in batch]
            jobs = [[pool.submit(evaluate_job, evaluator, tracker, p, s) for s in shared] for p in drawn]
            for trial, params, row in zip(batch, drawn, jobs):
                results = [j.result() for j in row]
                trial.set_user_attr("params", params)
                failures = [f"{k}: {r['error']}" for k, r in zip(keys, results) if "error" in r]
                if failures:
                    trial.set_user_attr("error", failures[0])
                    errors.append(failures[0])
                    study.tell(trial, state=TrialState.FAIL)
                else:
                    per_seq = [r["scores"] for r in results]
                    plain = [{m: float(v) for m, v in s.items()} for s in per_seq]  # JSON for the storage
                    trial.set_user_attr("scores", dict(zip(keys, plain)))
                    study.tell(trial, objective(per_seq, groups, crit))
                done += 1
                if progress is not None:
                    progress(done, trials, _best_value(study))
    complete = study.get_trials(deepcopy=False, states=(TrialState.COMPLETE,))
    if not complete:
        why = errors[0] if errors else "no trial completed"
        raise ValueError(f"{tracker}: no trial completed ({why})")
    best = study.best_trial
    first = min(study.get_trials(deepcopy=False), key=lambda t: t.number)
    return StudyResult(params=dict(best.user_attrs["params"]), value=float(best.value), trials=done,
                       study_name=name, chosen_on=keys, criterion=metric.lower(),
                       default_value=float(first.value) if first.state == TrialState.COMPLETE else None,
                       failed=len(study.get_trials(deepcopy=False, states=(TrialState.FAIL,))), errors=errors)


def _best_value(study: Any) -> float | None:
    try:
        return float(study.best_value)
    except ValueError:
        return None


__all__ = ["SAMPLERS", "StudyResult", "make_sampler", "run_study"]
