"""Where the shipped network weights live inside the package."""

from __future__ import annotations

from pathlib import Path

from lookalike.trackers.parts.weights_io import CheckpointError

WEIGHTS_DIR = Path(__file__).with_name("weights_data")


def shipped_weights_path(n_agents: int, n_slots: int, stem: str = "lstm") -> Path:
    """The shipped ``model.npz`` for set-up (M=n_slots, N=n_agents); a clear error when none ships.
    ``stem``: ``"lstm"`` (our input protocol) or ``"lstm_paper"`` (the robot-identification paper's)."""
    path = WEIGHTS_DIR / f"{stem}_m{n_slots}_n{n_agents}.npz"
    if not path.is_file():
        available = sorted(p.stem for p in WEIGHTS_DIR.glob("*.npz"))
        raise CheckpointError(
            f"no shipped weights for M={n_slots}, N={n_agents} ({path.name}); shipped: "
            f"{available or 'none'}. Use the set identifier (any team size), or train an LSTM with "
            f"`lookalike train --preset m{n_slots}n{n_agents}` and pass weights=PATH."
        )
    return path
