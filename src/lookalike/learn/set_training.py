"""Training the set associator over a range of team sizes (needs torch), with the LSTM's machinery
(:mod:`lookalike.learn.training`); validation averages the success rate over :data:`VALIDATION_TEAMS`."""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np

from lookalike._optional import needs
from lookalike.learn.checkpoints import changed_settings, load_checkpoint, save_checkpoint
from lookalike.learn.data import IGNORE
from lookalike.learn.set_data import SetBatchMaker, TeamSizes
from lookalike.learn.set_model import SetAssociator, SetSizes
from lookalike.learn.training import TRAIN_SEED_BASE, VALIDATION_SEED_BASE, TrainResult, _write_log
from lookalike.parallel import JobPool
from lookalike.trackers.set.network import SetWeights, save_set_weights

with needs("torch"):
    import torch
    from torch import nn

SET_SEED_OFFSET = 70_000_000  # keeps the set associator's seeds apart from the LSTM's
# (N, M, false positives per frame) of the validation sequences: the paper's three set-ups and others.
VALIDATION_TEAMS: tuple[tuple[int, int, float], ...] = (
    (2, 3, 0.5), (3, 5, 0.8), (7, 10, 1.5), (1, 2, 0.5), (4, 6, 1.0), (6, 8, 1.2), (9, 12, 1.5), (12, 14, 2.0),
)
# The paper's three set-ups (N, M, false positives per frame), drawn ``focus_prob`` of the time when fine-tuning.
FOCUS_TEAMS: tuple[tuple[int, int, float], ...] = ((2, 3, 0.5), (3, 5, 0.8), (7, 10, 1.5))


@dataclass(frozen=True)
class SetTrainConfig:
    """Hyper-parameters of one set-associator training run."""

    token: int = 32
    pair: int = 48
    memory: int = 48
    n_min: int = 1
    n_max: int = 12
    m_extra: int = 3
    fp_min: float = 0.3
    fp_max: float = 2.5
    learning_rate: float = 0.003
    lr_decay: float = 2e-4
    weight_decay: float = 0.0
    bptt: int = 150
    batch_size: int = 16
    sequence_length: int = 300
    steps: int = 3000
    minutes: float | None = None
    validation_sequences: int = 2
    validation_length: int = 450
    validation_every: int = 25
    patience: int = 12
    grad_clip: float = 1.0
    seed: int = 0
    swap_prob: float = 0.3
    swap_min_s: float = 1.0
    swap_max_s: float = 10.0
    swap_ends_s: float | None = None  # None: a swap may outlast the sequence (the first training's draws)
    focus_prob: float = 0.0  # fraction of batches on focus_teams (the paper's set-ups)
    focus_teams: tuple[tuple[int, int, float], ...] = FOCUS_TEAMS  # (N, M, fp) drawn uniformly; repeat one to weight it
    keep_snapshots: bool = False  # also write set_step{N}.npz at every validation
    noises: tuple[str, ...] = ()  # position-noise models drawn per sequence (("ours", "paper"): the noise mix)
    close_swap_prob: float = 0.0  # fraction of the swaps between the two robots of closest headings
    silent_swap_prob: float = 0.0  # fraction of the swaps that end inside a silence of one of the pair
    trainable: tuple[str, ...] = ()  # names (prefixes) of the parameters to train, e.g. ("gru",); empty: all

    def batch_maker(self, swap: bool = True) -> SetBatchMaker:
        """The batch generator of this run (with identity-swap augmentation unless ``swap`` is False)."""
        sizes = TeamSizes(self.n_min, self.n_max, self.m_extra, (self.fp_min, self.fp_max),
                          self.focus_teams if self.focus_prob > 0 else (), self.focus_prob)
        return SetBatchMaker(sizes, self.swap_prob if swap else 0.0, swap_s=(self.swap_min_s, self.swap_max_s),
                             swap_ends=self.swap_ends_s, noises=tuple(self.noises),
                             close_swap_prob=self.close_swap_prob, silent_swap_prob=self.silent_swap_prob)


def _to_torch(batch: tuple, device: str) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor, torch.Tensor, float]:
    a, d, v, y, dt = batch
    f = torch.float32
    return (torch.as_tensor(a, dtype=f, device=device), torch.as_tensor(d, dtype=f, device=device),
            torch.as_tensor(v, device=device), torch.as_tensor(y, device=device), float(dt))


def validation_batches(config: SetTrainConfig) -> list[tuple]:
    """One batch per team of :data:`VALIDATION_TEAMS`, fixed seeds apart from training and the benches."""
    return [SetBatchMaker(fixed=team)(VALIDATION_SEED_BASE + SET_SEED_OFFSET + i, config.validation_sequences,
                                      config.validation_length) for i, team in enumerate(VALIDATION_TEAMS)]


def validate(model: SetAssociator, batches: list[tuple], device: str = "cpu") -> float:
    """Mean over the batches of the per-detection argmax success rate."""
    model.eval()
    rates = []
    with torch.no_grad():
        for batch in batches:
            a, d, v, y, dt = _to_torch(batch, device)
            logp, _ = model(a, d, v, dt)
            used = y != IGNORE
            rates.append(float(((logp.argmax(-1) == y) & used).sum()) / max(int(used.sum()), 1))
    model.train()
    return float(np.mean(rates))


def _run_shape(config: dict) -> dict:
    """The configuration without the stopping rules and the learning rate (which a resumed run may change)."""
    return {k: v for k, v in config.items()
            if k not in ("steps", "minutes", "patience", "learning_rate", "keep_snapshots")}


def _export(model: SetAssociator, config: SetTrainConfig, info: dict) -> SetWeights:
    return SetWeights(model.export(), config.token, config.pair, config.memory, info={"config": asdict(config), **info})


def _new_model(config: SetTrainConfig, init: SetWeights | None) -> SetAssociator:
    """A fresh model of ``config``'s widths, with ``init``'s parameters when given."""
    model = SetAssociator(SetSizes(config.token, config.pair, config.memory))
    if init is not None:
        if (init.token, init.pair, init.memory) != (config.token, config.pair, config.memory):
            raise ValueError(f"init weights have widths {(init.token, init.pair, init.memory)}, the run "
                             f"{(config.token, config.pair, config.memory)}")
        model.load_exported(init.arrays)
    return model


def _trained(model: nn.Module, prefixes: tuple[str, ...]) -> list[nn.Parameter]:
    """The parameters of ``model`` whose names start with one of ``prefixes`` (all when empty); the others frozen."""
    if not prefixes:
        return list(model.parameters())
    kept = []
    for name, param in model.named_parameters():
        param.requires_grad_(name.startswith(prefixes))
        if param.requires_grad:
            kept.append(param)
    if not kept:
        names = sorted({n.split(".")[0] for n, _ in model.named_parameters()})
        raise ValueError(f"trainable {list(prefixes)}: no parameter of the set associator matches; its layers: "
                         f"{', '.join(names)}")
    return kept


def train_set(config: SetTrainConfig, out_dir: str | Path, resume: bool = False,
              on_step: Callable[[dict], None] | None = None, *, device: str = "cpu", pool: JobPool | None = None,
              init: SetWeights | None = None) -> TrainResult:
    """Train; write ``set.npz`` (best), ``checkpoint.pt`` and ``training_log.csv``; ``init``: weights to start from."""
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    if config.sequence_length % config.bptt:
        raise ValueError(f"sequence_length {config.sequence_length} must be a multiple of bptt {config.bptt}")
    torch.manual_seed(config.seed)
    model = _new_model(config, init).to(device)
    optimiser = torch.optim.Adam(_trained(model, config.trainable), lr=config.learning_rate,
                                 weight_decay=config.weight_decay)
    schedule = torch.optim.lr_scheduler.LambdaLR(optimiser, lambda t: 1.0 / (1.0 + config.lr_decay * t))
    loss_fn = nn.NLLLoss(ignore_index=IGNORE)
    ckpt_path, log_path, weights_path = out / "checkpoint.pt", out / "training_log.csv", out / "set.npz"
    step, best, best_step = 0, -1.0, 0
    history: list[dict] = []
    if resume and ckpt_path.is_file():
        state = load_checkpoint(ckpt_path, device)
        if _run_shape(state["config"]) != _run_shape(asdict(config)):
            changed = changed_settings(_run_shape(state["config"]), _run_shape(asdict(config)))
            raise ValueError(f"{ckpt_path}: was made with other settings: {changed}; run with the same settings, or "
                             "remove it or drop --resume")
        model.load_state_dict(state["model"])
        optimiser.load_state_dict(state["optimiser"])
        schedule.load_state_dict(state["schedule"])
        schedule.base_lrs = [config.learning_rate] * len(schedule.base_lrs)  # a resumed run may lower it
        step, best, best_step, history = state["step"], state["best"], state["best_step"], state["history"]
        for group in optimiser.param_groups:
            group["lr"] = config.learning_rate / (1.0 + config.lr_decay * schedule.last_epoch)
    val = validation_batches(config)
    maker = config.batch_maker()
    started = time.monotonic()
    stale = len([h for h in history if h["step"] > best_step])
    pool = pool or JobPool()
    ahead = 2 * pool.workers if (pool.workers > 1 or pool.backend == "ray") else 1
    pending: dict = {}
    base = TRAIN_SEED_BASE + SET_SEED_OFFSET + config.seed * 1_000_000
    while step < config.steps and stale < config.patience:
        if config.minutes is not None and time.monotonic() - started > 60 * config.minutes:
            break
        for k in range(step, min(step + ahead, config.steps)):
            if k not in pending:
                pending[k] = pool.submit(maker, base + k, config.batch_size, config.sequence_length)
        a, d, v, y, dt = _to_torch(pending.pop(step).result(), device)
        n_classes = a.shape[2] + 1
        state_h, losses = None, []
        for lo in range(0, config.sequence_length, config.bptt):
            sl = slice(lo, lo + config.bptt)
            logp, state_h = model(a[:, sl], d[:, sl], v[:, sl], dt, state_h)
            loss = loss_fn(logp.reshape(-1, n_classes), y[:, sl].reshape(-1))
            optimiser.zero_grad()
            loss.backward()
            nn.utils.clip_grad_norm_(model.parameters(), config.grad_clip)
            optimiser.step()
            schedule.step()
            state_h = tuple(s.detach() for s in state_h)
            losses.append(loss.item())
        step += 1
        row: dict[str, float] = {"step": step, "loss": float(np.mean(losses)), "lr": float(schedule.get_last_lr()[0]),
                                 "val_success": math.nan, "seconds": time.monotonic() - started, "n_agents": a.shape[2]}
        if step % config.validation_every == 0 or step == config.steps:
            row["val_success"] = validate(model, val, device)
            history.append(row)
            if row["val_success"] > best:
                best, best_step, stale = row["val_success"], step, 0
                save_set_weights(_export(model, config, {"val_success": best, "step": step}), weights_path)
            else:
                stale += 1
            if config.keep_snapshots:
                save_set_weights(_export(model, config, {"val_success": row["val_success"], "step": step}),
                                 out / f"set_step{step}.npz")
            save_checkpoint({"config": asdict(config), "model": model.state_dict(),
                             "optimiser": optimiser.state_dict(), "schedule": schedule.state_dict(), "step": step,
                             "best": best, "best_step": best_step, "history": history}, ckpt_path)
            _write_log(log_path, history)
        if on_step is not None:
            on_step(row)
    if best < 0:  # stopped before the first validation
        row = {"step": step, "loss": math.nan, "lr": float(schedule.get_last_lr()[0]),
               "val_success": validate(model, val, device), "seconds": time.monotonic() - started, "n_agents": 0}
        history.append(row)
        best, best_step = row["val_success"], step
        save_set_weights(_export(model, config, {"val_success": best, "step": step}), weights_path)
        _write_log(log_path, history)
    return TrainResult(best, best_step, step, weights_path, log_path, history)
