"""Training the association network on simulated sequences (needs torch): Adam with ``lr / (1 + decay·t)``, truncated
BPTT, validation on fixed held-out seeds, early stopping, resumable checkpoints, a CSV log; batches are pure functions
of their seeds, made ahead by a :class:`~lookalike.parallel.JobPool`."""

from __future__ import annotations

import csv
import io
import math
import time
from collections.abc import Callable, Sequence
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from lookalike._files import replace_file, write_bytes
from lookalike._optional import needs
from lookalike.learn.checkpoints import changed_settings, load_checkpoint, save_checkpoint
from lookalike.learn.data import IGNORE, success_rate
from lookalike.learn.model import AssociationNet
from lookalike.parallel import JobPool
from lookalike.trackers.lstm.checkpoint import NetworkWeights, save_weights
from lookalike.trackers.lstm.encoding import EncodingSpec

with needs("torch"):
    import torch
    from torch import nn

TRAIN_SEED_BASE = 2_000_000_000  # training sequences use seeds from here on
VALIDATION_SEED_BASE = 1_900_000_000  # fixed held-out validation seeds


@dataclass(frozen=True)
class TrainConfig:
    """Hyper-parameters of one training run (the paper's values where it gives them)."""

    n_agents: int
    n_slots: int
    relative_headings: bool = True
    cell: str = "lstm"
    hidden: int = 64
    num_layers: int = 5
    learning_rate: float = 0.004
    lr_decay: float = 1e-4
    weight_decay: float = 1e-6
    bptt: int = 150
    batch_size: int = 16
    sequence_length: int = 600
    steps: int = 2000
    minutes: float | None = None
    validation_sequences: int = 8
    validation_every: int = 50
    patience: int = 12
    grad_clip: float = 1.0
    seed: int = 0
    swap_prob: float = 0.0  # recorded here; the sampler applies it (sim_data.SimSampler)
    init_from: str | None = None  # weights the run started from (recorded; passed as ``init``)
    protocol: str = "ours"  # input layout: "ours" or "paper" (the paper's N + 4M inputs)
    noise: str = "ours"  # simulator noise model(s) of the sampler (recorded): ours, paper or mix


@dataclass
class TrainResult:
    """What a run produced: the best validation success rate and where things were written."""

    best_success: float
    best_step: int
    steps: int
    weights_path: Path
    log_path: Path
    history: list[dict] = field(default_factory=list)


# (seed, n_frames, rng for slot shuffling) -> inputs (T, n_inputs), targets (T, M)
Sampler = Callable[[int, int, "np.random.Generator | None"], tuple[np.ndarray, np.ndarray]]


def make_batch(sample: Sampler, seeds: Sequence[int], length: int) -> tuple[np.ndarray, np.ndarray]:
    """Inputs ``(B, T, n_inputs)`` and targets ``(B, T, M)``, a function of ``seeds`` alone."""
    xs, ys = zip(*(sample(int(s), length, np.random.default_rng([int(s), 1])) for s in seeds))
    return np.stack(xs), np.stack(ys)


def _validate(model: AssociationNet, x: torch.Tensor, y: np.ndarray) -> float:
    model.eval()
    with torch.no_grad():
        logp, _ = model(x)
    model.train()
    correct, total = success_rate(logp.cpu().numpy(), y)
    return correct / max(total, 1)


def _train_chunks(model: Any, xt: Any, yt: Any, config: TrainConfig, n_classes: int, loss_fn: Any, optimiser: Any,
                  schedule: Any) -> list[float]:
    """One optimisation step per ``bptt`` chunk with a label; the losses."""
    state_h, losses = None, []
    for lo in range(0, config.sequence_length, config.bptt):
        target = yt[:, lo : lo + config.bptt]
        logp, state_h = model(xt[:, lo : lo + config.bptt], state_h)
        if not bool((target != IGNORE).any()):
            state_h = tuple(s.detach() for s in state_h) if isinstance(state_h, tuple) else state_h.detach()
            continue
        loss = loss_fn(logp.reshape(-1, n_classes), target.reshape(-1))
        optimiser.zero_grad()
        loss.backward()
        nn.utils.clip_grad_norm_(model.parameters(), config.grad_clip)
        optimiser.step()
        schedule.step()
        state_h = tuple(s.detach() for s in state_h) if isinstance(state_h, tuple) else state_h.detach()
        losses.append(loss.item())
    return losses

def train(config: TrainConfig, sample: Sampler, out_dir: str | Path, resume: bool = False,
          on_step: Callable[[dict], None] | None = None, *, device: str = "cpu", pool: JobPool | None = None,
          init: NetworkWeights | None = None, validation_sample: Sampler | None = None,
          validation: tuple[np.ndarray, np.ndarray] | None = None, info: dict | None = None) -> TrainResult:
    """Train on sequences from ``sample(seed, n_frames, rng)``; write weights, checkpoint and log to ``out_dir``.
    ``init``: exported weights of the same shape to start from (validated first); ``validation_sample`` or
    ``validation`` (``(B, T, n_inputs), (B, T, M)``) set the validation data; ``info`` goes into the metadata."""
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    torch.manual_seed(config.seed)
    spec = EncodingSpec(config.n_agents, config.n_slots, relative_headings=config.relative_headings,
                        protocol=config.protocol)
    if config.sequence_length % config.bptt:
        raise ValueError(f"sequence_length {config.sequence_length} must be a multiple of bptt {config.bptt}")
    val_x, val_y = validation if validation is not None else make_batch(
        validation_sample or sample, [VALIDATION_SEED_BASE + i for i in range(config.validation_sequences)],
        config.sequence_length)
    model = AssociationNet(spec, config.hidden, config.num_layers, config.cell)
    if init is not None:
        model.load_exported(init)
    else:
        flat = val_x.reshape(-1, spec.n_inputs)
        model.set_normalisation(flat.mean(0), flat.std(0))
    model.to(device)
    val_xt = torch.as_tensor(val_x, device=device)
    optimiser = torch.optim.Adam(model.parameters(), lr=config.learning_rate, weight_decay=config.weight_decay)
    schedule = torch.optim.lr_scheduler.LambdaLR(optimiser, lambda t: 1.0 / (1.0 + config.lr_decay * t))
    loss_fn = nn.NLLLoss(ignore_index=IGNORE)
    ckpt_path, log_path = out / "checkpoint.pt", out / "training_log.csv"
    weights_path = out / "model.npz"
    step, best, best_step, history = 0, -1.0, 0, []
    if resume and ckpt_path.is_file():
        state = load_checkpoint(ckpt_path, device)
        if state["config"] != asdict(config):
            changed = changed_settings(state["config"], asdict(config))
            raise ValueError(f"{ckpt_path}: was made with other settings: {changed}; run with the same settings, or "
                             "remove it or drop --resume")
        model.load_state_dict(state["model"])
        optimiser.load_state_dict(state["optimiser"])
        schedule.load_state_dict(state["schedule"])
        step, best, best_step, history = state["step"], state["best"], state["best_step"], state["history"]
    started = time.monotonic()
    extra = dict(info or {})
    notify = on_step or (lambda row: None)
    if init is not None and not history:  # the starting weights are the first candidate
        best = _validate(model, val_xt, val_y)
        history.append({"step": 0, "loss": math.nan, "lr": config.learning_rate, "val_success": best, "seconds": 0.0})
        save_weights(model.export({**extra, "config": asdict(config), "val_success": best, "step": 0}), weights_path)
        _write_log(log_path, history)
        notify(history[0])
    stale = len([h for h in history if h["step"] > best_step])
    pool = pool or JobPool()
    ahead = 2 * pool.workers if (pool.workers > 1 or pool.backend == "ray") else 1
    pending = {}
    while step < config.steps:
        if config.minutes is not None and time.monotonic() - started > 60 * config.minutes:
            break
        for k in range(step, min(step + ahead, config.steps)):
            if k not in pending:
                first = TRAIN_SEED_BASE + config.seed * 10_000_000 + k * config.batch_size
                seeds = first + np.arange(config.batch_size)
                pending[k] = pool.submit(make_batch, sample, seeds, config.sequence_length)
        x, y = pending.pop(step).result()
        xt, yt = torch.as_tensor(x, device=device), torch.as_tensor(y, device=device)
        losses = _train_chunks(model, xt, yt, config, spec.n_classes, loss_fn, optimiser, schedule)
        step += 1
        row: dict[str, float] = {"step": step, "loss": float(np.mean(losses)) if losses else math.nan,
                                 "lr": float(schedule.get_last_lr()[0]),
               "val_success": math.nan, "seconds": time.monotonic() - started}
        if step % config.validation_every == 0 or step == config.steps:
            row["val_success"] = _validate(model, val_xt, val_y)
            history.append(row)
            if row["val_success"] > best:
                best, best_step, stale = row["val_success"], step, 0
                meta = {**extra, "config": asdict(config), "val_success": best, "step": step}
                save_weights(model.export(meta), weights_path)
            else:
                stale += 1
            save_checkpoint(
                {"config": asdict(config), "model": model.state_dict(), "optimiser": optimiser.state_dict(),
                 "schedule": schedule.state_dict(), "step": step, "best": best, "best_step": best_step,
                 "history": history},
                ckpt_path,
            )
            _write_log(log_path, history)
        notify(row)
        if stale >= config.patience:
            break
    if best < 0:  # stopped before the first validation
        row = {"step": step, "loss": math.nan, "lr": float(schedule.get_last_lr()[0]),
               "val_success": _validate(model, val_xt, val_y), "seconds": time.monotonic() - started}
        history.append(row)
        best, best_step = row["val_success"], step
        save_weights(model.export({**extra, "config": asdict(config), "val_success": best, "step": step}),
                     weights_path)
        _write_log(log_path, history)
    return TrainResult(best, best_step, step, weights_path, log_path, history)



def _write_log(path: Path, history: list[dict]) -> None:
    """Write the whole ``history`` to ``path`` through a temporary file renamed into place (a run killed while
    writing it keeps the earlier log whole)."""
    text = io.StringIO(newline="")
    writer = csv.DictWriter(text, fieldnames=list(history[0]))
    writer.writeheader()
    writer.writerows(history)
    write_bytes(path, text.getvalue().encode())


def plot_log(log_path: str | Path, png_path: str | Path) -> Path:
    """Plot a training log (loss and validation success rate against step) to PNG."""
    with needs("matplotlib"):
        import matplotlib

    matplotlib.use("Agg")
    with needs("matplotlib"):
        import matplotlib.pyplot as plt

    with Path(log_path).open() as fh:
        rows = list(csv.DictReader(fh))
    step = [int(r["step"]) for r in rows]
    fig, ax = plt.subplots(figsize=(7, 4))
    ax.plot(step, [float(r["loss"]) for r in rows], color="tab:blue", label="training loss")
    ax.set_xlabel("step")
    ax.set_ylabel("loss (NLL per slot)")
    ax2 = ax.twinx()
    ax2.plot(step, [100 * float(r["val_success"]) for r in rows], color="tab:green", label="validation")
    ax2.set_ylabel("validation success rate (%)")
    fig.legend(loc="upper right")
    fig.tight_layout()
    replace_file(Path(png_path), lambda f: fig.savefig(f, dpi=100, format="png"))
    plt.close(fig)
    return Path(png_path)
