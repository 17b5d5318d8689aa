"""``lookalike train --search N``: Optuna search over the LSTM's size, depth and learning rate."""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from rich.progress import TextColumn

from lookalike.cli.app import check_choice, console, failing
from lookalike.cli.progress import bars
from lookalike.cli.train_options import RunOptions


@dataclass(frozen=True)
class SearchOptions(RunOptions):
    """The ``lookalike train`` options that apply with ``--search``."""

    cell: str
    relative: bool
    sampler: str
    study: str | None
    space: str


def train_search(trials: int, output: Path, preset_name: str, opt: SearchOptions) -> None:
    """Run (or continue) the search; print each trial and the choice; write ``OUTPUT/search.json`` and
    ``OUTPUT/model.npz``."""
    from lookalike.learn.search import SAMPLERS, SearchSpace, run_search
    from lookalike.learn.training import TrainConfig
    from lookalike.sim import preset

    check_choice("--sampler", opt.sampler, SAMPLERS)
    with failing(ValueError):
        space = SearchSpace.parse(opt.space)
        world = preset(preset_name)
        base = TrainConfig(n_agents=world.n_agents, n_slots=world.max_detections, relative_headings=opt.relative,
                           cell=opt.cell, batch_size=opt.batch_size, sequence_length=opt.sequence_length,
                           steps=opt.steps, minutes=opt.minutes, seed=opt.seed, patience=opt.patience,
                           validation_every=opt.validate_every)
    with bars("search {task.description}", TextColumn("best {task.fields[best]}"), transient=False) as progress:
        task = progress.add_task(preset_name, total=trials, best="–")

        def on_trial(done: int, total: int, row: dict[str, Any]) -> None:
            value = f"{100 * row['value']:.1f}%" if "value" in row else f"failed ({row['error']})"
            progress.console.print(
                f"trial {row['trial']}: hidden {row['hidden']}, layers {row['num_layers']}, learning rate "
                f"{row['learning_rate']:.2g} → validation {value}")
            best = row["best"]
            progress.update(task, completed=done, best="–" if math.isnan(best) else f"{100 * best:.1f}%")

        with failing(ValueError):
            result = run_search(base, world, output, trials, space=space, sampler=opt.sampler, storage=opt.study,
                                study_name=f"lstm-{preset_name}", workers=opt.workers, backend=opt.backend,
                                address=opt.address, threads=opt.threads, progress=on_trial)
    p = result.params
    console.print(
        f"chosen: hidden {p['hidden']}, layers {p['num_layers']}, learning rate {p['learning_rate']:.3g} (trial "
        f"{result.best_trial} of {result.trials}, {result.failed} failed): validation success rate "
        f"[bold]{100 * result.value:.1f}%[/] (chosen on it), {100 * result.check_success:.1f}% on "
        f"{result.check_sequences} other held-out sequences; weights {result.weights_path}, "
        f"choice {result.summary_path}")
