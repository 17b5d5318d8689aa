"""The ``lookalike train`` options every training run shares (``--search`` and ``--recordings`` add theirs)."""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class RunOptions:
    """How long and how a training run goes: steps, time limit (minutes), batch, sequence length
    (frames), seed, patience and validation interval (steps), threads and the parallel backend."""

    steps: int
    minutes: float | None
    batch_size: int
    sequence_length: int
    seed: int
    patience: int
    validate_every: int
    threads: int
    workers: int
    backend: str
    address: str | None
