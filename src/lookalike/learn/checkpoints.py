"""Training checkpoints (``checkpoint.pt``, needs torch): written whole or not at all (an interrupted run leaves the
previous one), read back with a one-line error naming the file; and the settings a resumed run changed."""

from __future__ import annotations

import os
import tempfile
from pathlib import Path
from typing import Any

from lookalike._optional import needs

KEYS = frozenset({"config", "model", "optimiser", "schedule", "step", "best", "best_step", "history"})


def save_checkpoint(state: dict[str, Any], path: Path) -> None:
    """Write ``state`` to ``path`` through a temporary file in the same folder renamed into place."""
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    os.close(fd)
    try:
        _torch().save(state, tmp)
        os.replace(tmp, path)
    finally:
        Path(tmp).unlink(missing_ok=True)


def load_checkpoint(path: Path, device: Any) -> dict[str, Any]:
    """The state :func:`save_checkpoint` wrote; ``ValueError`` naming ``path`` when it is damaged or not one."""
    try:
        state = _torch().load(path, weights_only=False, map_location=device)
    except Exception as exc:  # noqa: BLE001 (torch and pickle raise many kinds for a damaged file)
        reason = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
        raise ValueError(f"{path}: not a readable training checkpoint ({reason}); remove it or drop --resume") from None
    if not isinstance(state, dict) or not KEYS <= state.keys():
        raise ValueError(f"{path}: not a checkpoint of this training; remove it or drop --resume")
    return state


def changed_settings(old: dict[str, Any], new: dict[str, Any]) -> str:
    """The settings that differ between ``old`` and ``new``, e.g. ``steps 10 (now 20), cell 'lstm' (now 'gru')``."""
    keys = [k for k in (*old, *(k for k in new if k not in old)) if old.get(k) != new.get(k)]
    return ", ".join(f"{k} {old.get(k)!r} (now {new.get(k)!r})" for k in keys)


def _torch() -> Any:
    with needs("torch"):
        import torch
    return torch
