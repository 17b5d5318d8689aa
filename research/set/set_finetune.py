"""The fine-tuning of the shipped ``set`` weights towards the paper's small set-ups (issue 23).

``python research/set/set_finetune.py OUT --minutes 80`` starts from the shipped weights and trains
with :data:`FINETUNE_CONFIG`: a low, decaying learning rate, 60% of the batches on the paper's set-ups
(M=3, N=2 three times as often as M=10, N=7, M=5, N=3 twice), the other 40% over every team size
(N 1–12), identity swaps of 1–6 s that end inside the sequence, and a snapshot at every validation
(``OUT/set_step{N}.npz``) to choose among on tuning sequences. ``--stage 2`` runs
:data:`FINETUNE2_CONFIG` instead: a second stage from the weights shipped after the first, with more
M=3, N=2 batches and more, longer identity swaps. ``--stage 4`` runs :data:`FINETUNE4_CONFIG`: the
noise mix (ours + paper position noise) and swaps between robots of close headings. ``--stage 16`` runs
:data:`FINETUNE16_CONFIG`: swaps whose end falls inside one agent's silence. Needs torch.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

from lookalike.learn.set_training import SetTrainConfig

FINETUNE_TEAMS: tuple[tuple[int, int, float], ...] = (
    (2, 3, 0.5), (2, 3, 0.5), (2, 3, 0.5), (3, 5, 0.8), (3, 5, 0.8), (7, 10, 1.5),
)
FINETUNE_CONFIG = SetTrainConfig(
    learning_rate=0.0002, lr_decay=0.001, steps=5000, minutes=80.0, patience=1000, seed=3,
    swap_prob=0.3, swap_min_s=1.0, swap_max_s=6.0, swap_ends_s=2.0,
    focus_prob=0.6, focus_teams=FINETUNE_TEAMS, keep_snapshots=True, validation_every=25,
)
# The second stage: M=3, N=2 four times as often as M=5, N=3, M=10, N=7 twice.
FINETUNE2_TEAMS: tuple[tuple[int, int, float], ...] = (
    (2, 3, 0.5), (2, 3, 0.5), (2, 3, 0.5), (2, 3, 0.5), (3, 5, 0.8), (7, 10, 1.5), (7, 10, 1.5),
)
FINETUNE2_CONFIG = SetTrainConfig(
    learning_rate=0.0001, lr_decay=0.001, steps=5000, minutes=55.0, patience=1000, seed=4,
    swap_prob=0.5, swap_min_s=1.0, swap_max_s=10.0, swap_ends_s=3.0,
    focus_prob=0.7, focus_teams=FINETUNE2_TEAMS, keep_snapshots=True, validation_every=25,
)
# The fourth stage (issue 23): the noise mix (ours + paper position noise, one per sequence, as the LSTM's
# fine-tune), the first stage's team weights with more focus, swaps that end inside the sequence, half of
# them between the two robots of closest headings (so the memory learns to yield to the reports there).
FINETUNE4_CONFIG = SetTrainConfig(
    learning_rate=0.0002, lr_decay=0.001, steps=5000, minutes=48.0, patience=1000, seed=5,
    swap_prob=0.5, swap_min_s=1.0, swap_max_s=10.0, swap_ends_s=3.0, close_swap_prob=0.5,
    focus_prob=0.7, focus_teams=FINETUNE_TEAMS, keep_snapshots=True, validation_every=25,
    noises=("ours", "paper"),
)
# The sixteenth stage (issue 23): the first stage's mix (what ships) at half its learning rate, swaps in half of
# the sequences (a quarter of them between the closest headings), half of the swaps ending inside one agent's silence.
FINETUNE16_CONFIG = SetTrainConfig(
    learning_rate=0.0001, lr_decay=0.001, steps=5000, minutes=40.0, patience=1000, seed=16,
    swap_prob=0.5, swap_min_s=1.0, swap_max_s=10.0, swap_ends_s=3.0, close_swap_prob=0.25, silent_swap_prob=0.5,
    focus_prob=0.6, focus_teams=FINETUNE_TEAMS, keep_snapshots=True, validation_every=25,
)
STAGES = {1: FINETUNE_CONFIG, 2: FINETUNE2_CONFIG, 4: FINETUNE4_CONFIG, 16: FINETUNE16_CONFIG}


def main(argv: list[str] | None = None) -> None:
    """Run the fine-tuning into ``OUT`` from ``--init`` (default: the shipped set weights)."""
    import dataclasses

    import torch

    from lookalike.learn.set_training import train_set
    from lookalike.trackers.set.network import SHIPPED_SET_WEIGHTS, load_set_weights

    parser = argparse.ArgumentParser(prog="python research/set/set_finetune.py", description=__doc__)
    parser.add_argument("out", type=Path, help="output folder (snapshots, log, best-validation weights)")
    parser.add_argument("--stage", type=int, choices=sorted(STAGES), default=1,
                        help="1: FINETUNE_CONFIG, 2: FINETUNE2_CONFIG (from the stage-1 weights), "
                        "4: FINETUNE4_CONFIG (the noise mix and close-heading swaps, from the shipped weights), "
                        "16: FINETUNE16_CONFIG (swaps that end in a silence, from the shipped weights)")
    parser.add_argument("--minutes", type=float, default=None, help="wall-clock limit (default: the stage's)")
    parser.add_argument("--init", type=Path, default=SHIPPED_SET_WEIGHTS, help="weights to start from (.npz)")
    parser.add_argument("--trainable", default=None,
                        help="comma-separated layers to train, the rest frozen (e.g. gru; default: all)")
    parser.add_argument("--learning-rate", type=float, default=None,
                        help="initial learning rate (default: the stage's)")
    args = parser.parse_args(argv)
    torch.set_num_threads(1)
    stage = STAGES[args.stage]
    config = dataclasses.replace(
        stage, minutes=stage.minutes if args.minutes is None else args.minutes,
        learning_rate=stage.learning_rate if args.learning_rate is None else args.learning_rate,
        trainable=tuple(args.trainable.split(",")) if args.trainable else stage.trainable)
    started = time.monotonic()

    def on_step(row: dict) -> None:
        print(f"{row['step']} loss={row['loss']:.4f} lr={row['lr']:.2e} val={row['val_success']:.4f} "
              f"N={row['n_agents']} t={time.monotonic() - started:.0f}s", flush=True)

    result = train_set(config, args.out, on_step=on_step, init=load_set_weights(args.init))
    print(f"done: best validation {result.best_success:.4f} at step {result.best_step} of {result.steps}", flush=True)


if __name__ == "__main__":
    main()
