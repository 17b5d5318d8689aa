"""``lookalike tune``: choose a tracker's parameters on labelled data (Optuna), write a parameter file."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import typer
from rich.markup import escape
from rich.progress import TaskID, TimeRemainingColumn
from rich.table import Table

from lookalike.cli.app import (
    app,
    check_choice,
    check_outputs_or_fail,
    check_study_or_fail,
    console,
    fail,
    failing,
    require,
)
from lookalike.cli.progress import bars
from lookalike.parallel import BACKENDS


def _pct(scores: dict[str, float]) -> str:
    return " / ".join(f"{100 * scores[m]:.2f}" for m in ("HOTA", "IDF1", "MOTA"))


@app.command()
def tune(
    data: list[str] | None = typer.Argument(
        None, help="Labelled data: MOTChallenge sequence folders (gt/gt.txt, det/det.txt, seqinfo.ini) or a folder "
        "of them, and/or bench datasets by name (mot15, pigs, hexbug, mot17-synth...); each one is a dataset, and "
        "the criterion is the mean of the datasets' figures."),
    output: Path | None = typer.Option(None, "-o", "--output", help="Parameter file to write (JSON)."),
    tracker: str = typer.Option("boxtrack", "--tracker", "-t", help="Registered tracker name."),
    trials: int = typer.Option(50, "--trials", min=1, help="Trials in the study in all (a resumed study "
                                "runs the rest)."),
    sampler: str = typer.Option("tpe", "--sampler", help="'tpe' (Tree-structured Parzen Estimator) or 'random'."),
    seed: int = typer.Option(0, "--seed", help="Seed of the sampler."),
    folds: str = typer.Option("none", "--folds", help="Also estimate the score on unseen data: 'loso' (leave one "
                              "sequence out), 'lodo' (one dataset out) or K folds; each fold runs its own study on the "
                              "other sequences. 'none': no estimate."),
    metric: str = typer.Option("hota+idf1+mota", "--metric", help="Criterion: hota+idf1+mota, hota or idf1."),
    workers: int = typer.Option(1, "--workers", min=1, help="Local processes (or Ray CPUs for a local Ray)."),
    backend: str = typer.Option("local", "--backend", help=f"One of {', '.join(BACKENDS)}."),
    address: str | None = typer.Option(None, "--address", help="Ray cluster address (default: a local ray.init())."),
    study: str | None = typer.Option(None, "--study", help="Optuna storage URL to save the study, e.g. "
                                     "sqlite:///study.db (default: in memory)."),
    study_name: str | None = typer.Option(None, "--study-name", help="Study name in the storage "
                                          "(default: the tracker)."),
    resume: bool = typer.Option(False, "--resume", help="Continue the study saved in --study."),
    space_path: Path | None = typer.Option(None, "--space", help="Search space JSON (see --show-space), replacing the "
                                           "default one."),
    show_space: bool = typer.Option(False, "--show-space", help="Print the tracker's default search space and exit."),
    data_root: Path | None = typer.Option(None, "--data", help="Folder of the bench datasets (default: $LOOKALIKE_DATA "
                                          "or ../shared/data)."),
) -> None:
    """Choose a tracker's parameters on labelled sequences; write them for `track --params`."""
    from lookalike.tune import space_to_json

    space = _load_space(tracker, space_path)
    if show_space:
        console.print_json(json.dumps(space_to_json(space)))
        return
    if not data:
        fail("DATA: give at least one sequence folder or bench dataset")
    if output is None:
        fail("-o/--output: give the parameter file to write")
    from lookalike.tune import CRITERIA, SAMPLERS

    check_choice("--sampler", sampler, SAMPLERS)
    check_choice("--metric", metric, list(CRITERIA))
    check_choice("--backend", backend, BACKENDS)
    if resume and study is None:
        fail("--resume: needs --study (the storage the study was saved in)")
    require("optuna", *(["ray"] if backend == "ray" else []))
    from lookalike.io.outputs import sqlite_file

    check_outputs_or_fail({"-o/--output": output, "--study": sqlite_file(study)}, _data_inputs(data, space_path))
    check_study_or_fail(study)
    seqs, fold_list = _load_data(data, data_root, folds)
    console.print(f"{tracker}: {len(seqs)} sequence(s), {trials} trials ({sampler}), criterion {metric}, "
                  f"{len(space)} parameters in the space")
    common: dict[str, Any] = dict(space=space, trials=trials, sampler=sampler, seed=seed, metric=metric,
                                  workers=workers, backend=backend, address=address, storage=study, resume=resume)
    result, choices = _run(tracker, seqs, fold_list, study_name, metric, trials, common)
    path, held = _save(output, tracker, result, choices, space, sampler, seed, folds)
    _print_results(tracker, metric, folds, seqs, result, choices, held, path)


def _load_space(tracker: str, space_path: Path | None) -> Any:
    """The tracker's search space: its default one, or the one in ``space_path``."""
    from lookalike.trackers import tracker_names
    from lookalike.tune.space import default_space, read_space

    if tracker not in tracker_names():
        fail(f"unknown tracker {tracker!r}; choose one of: {', '.join(tracker_names())}")
    with failing(OSError, ValueError, prefix="--space: "):
        space = default_space(tracker)
        if space_path is not None:
            space = read_space(space_path, tracker)
    return space


def _data_inputs(data: list[str], space_path: Path | None) -> list[Path]:
    """The files and folders ``tune`` reads from (the given sequence folders and their files, the space)."""
    from lookalike.cli.app import sequence_files

    folders = [Path(d) for d in data if Path(d).exists()]
    return [*folders, *(f for path in folders for f in sequence_files(path)), *([space_path] if space_path else [])]


def _load_data(data: list[str], data_root: Path | None, folds: str) -> tuple[Any, Any]:
    """The labelled sequences and the folds (None for ``--folds none``)."""
    from lookalike.bench.datasets import DATASETS, resolve_data_root
    from lookalike.tune import load_tuning_data, make_folds

    with failing(ValueError, FileNotFoundError):
        root = None
        if any(not Path(d).exists() and d in DATASETS for d in data):  # (a missing folder: named as such below)
            root = resolve_data_root(data_root)
        seqs = load_tuning_data(data, root)
        keys = [f"{s.dataset}/{s.name}" for s in seqs]
        fold_list = None if folds.lower() == "none" else make_folds(keys, folds, [s.dataset for s in seqs])
    return seqs, fold_list


def _run(tracker: str, seqs: Any, fold_list: Any, study_name: str | None, metric: str, trials: int,
         common: dict[str, Any]) -> tuple[Any, Any]:
    """The study on all sequences, and the per-fold choices (None without folds)."""
    from lookalike.tune import leave_one_out_selection, run_study

    with failing(ValueError):
        with bars("{task.description}", TimeRemainingColumn()) as bar:
            task = bar.add_task("trials", total=trials)

            def step(done: int, total: int, best: float | None) -> None:
                best_text = "–" if best is None else f"{100 * best:.2f}"
                bar.update(task, completed=done, description=f"trials (best {metric} {best_text})")

            result = run_study(tracker, seqs, study_name=study_name, progress=step, **common)
        choices = None
        if fold_list is not None:
            with bars("{task.description}", TimeRemainingColumn()) as bar:
                tasks: dict[str, TaskID] = {}

                def fold_step(fold: str, done: int, total: int, best: float | None) -> None:
                    if fold not in tasks:
                        tasks[fold] = bar.add_task(f"fold {fold}", total=total)
                    bar.update(tasks[fold], completed=done)

                choices = leave_one_out_selection(tracker, seqs, folds=fold_list, study_name=study_name,
                                                  progress=fold_step, **common)
    return result, choices


def _save(output: Path, tracker: str, result: Any, choices: Any, space: Any, sampler: str, seed: int,
          folds: str) -> tuple[Any, Any]:
    """Write the parameter file; its path and the combined left-out scores (None without folds)."""
    from lookalike.tune import combined_left_out, save_params, space_to_json

    extra: dict[str, object] = {"score": result.value, "default_score": result.default_value, "sampler": sampler,
                                "seed": seed, "space": space_to_json(space)}
    held = None
    if choices is not None:
        held = combined_left_out(choices)
        extra["left_out"] = {"folds": folds, "combined": {m: held[m] for m in ("HOTA", "IDF1", "MOTA")},
                             "per_fold": [{"left_out": c.left_out, "chosen_on": c.chosen_on, "score": c.test_value,
                                           "params": c.params} for c in choices]}
    with failing(ValueError):
        path = save_params(output, tracker, result.params, chosen_on=result.chosen_on, criterion=result.criterion,
                           trials=result.trials, **extra)
    return path, held


def _print_results(tracker: str, metric: str, folds: str, seqs: Any, result: Any, choices: Any, held: Any,
                   path: Any) -> None:
    default = "–" if result.default_value is None else f"{100 * result.default_value:.2f}"
    console.print(f"best {metric} on the {len(seqs)} sequence(s) it was chosen on: {100 * result.value:.2f} "
                  f"(defaults {default}); {result.failed} failed trial(s)")
    if result.errors:
        console.print(f"[yellow]first failure: {escape(str(result.errors[0]))}[/yellow]")
    table = Table(title=f"{tracker} parameters → {path}")
    table.add_column("Parameter")
    table.add_column("Value", justify="right")
    for k, v in result.params.items():
        table.add_row(k, f"{v:.4g}" if isinstance(v, float) else str(v))
    console.print(table)
    if choices is not None:
        table = Table(title=f"Left-out scores ({folds}): each fold chosen on the other sequences only")
        for column in ("Left out", "HOTA / IDF1 / MOTA", metric):
            table.add_column(column, justify="left" if column == "Left out" else "right")
        for c in choices:
            table.add_row(", ".join(c.left_out), _pct(c.test_scores), f"{100 * c.test_value:.2f}")
        table.add_row("all (combined)", _pct(held), "")
        console.print(table)
        console.print("The left-out scores estimate what these choices give on data like this that nobody tuned on.")
    else:
        console.print("This score is on the sequences the choice was made on; --folds loso estimates unseen data.")


__all__ = ["tune"]
