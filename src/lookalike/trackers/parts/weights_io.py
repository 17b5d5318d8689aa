"""Network weights stored as an ``.npz`` with a ``.json`` of metadata beside it: reading the metadata, and the error
a corrupt or mismatched file raises."""

from __future__ import annotations

import json
import os
import tempfile
from collections.abc import Callable
from pathlib import Path
from typing import Any, BinaryIO

import numpy as np


class CheckpointError(ValueError):
    """A weights file that is corrupt, of another version, or does not fit the requested set-up."""


def read_metadata(path: str | os.PathLike[str], fmt: str, what: str) -> tuple[Path, Path, dict[str, Any]]:
    """``(weights .npz path, metadata .json path, parsed metadata)`` of weights stored as an ``.npz``
    with a ``.json`` beside it; :class:`CheckpointError` naming the file when either is missing, the
    JSON is invalid or its ``format`` is not ``fmt`` (``what`` names the expected kind in the message)."""
    given = Path(path)
    if given.suffix not in ("", ".npz", ".json"):
        raise CheckpointError(f"{given}: not exported weights (an .npz with its .json beside it, such as a training "
                              "run's model.npz)")
    path = given.with_suffix(".npz")
    meta_path = path.with_suffix(".json")
    if not path.is_file():
        raise CheckpointError(f"{path}: no such file (exported weights are an .npz with its .json beside it)")
    if not meta_path.is_file():
        raise CheckpointError(f"{meta_path}: missing; exported weights are {path.name} and {meta_path.name} side by "
                              "side")
    try:
        meta = json.loads(meta_path.read_text())
    except json.JSONDecodeError as exc:
        raise CheckpointError(f"{meta_path}: not valid JSON ({exc})") from None
    if not isinstance(meta, dict) or meta.get("format") != fmt:
        found = meta.get("format") if isinstance(meta, dict) else None
        raise CheckpointError(f"{meta_path}: not a {what} (format {found!r})")
    return path, meta_path, meta


def write_weights(path: Path, arrays: dict[str, Any], meta: dict[str, Any], *, compressed: bool = False) -> None:
    """Write ``path`` (``.npz``) and its ``.json`` metadata, each through a unique temporary file in the same folder
    renamed into place (a killed run leaves the old files whole and no temporary behind)."""
    save = np.savez_compressed if compressed else np.savez
    _replace(path, lambda f: save(f, **arrays))
    text = json.dumps(meta, indent=2, sort_keys=True) + "\n"
    _replace(path.with_suffix(".json"), lambda f: f.write(text.encode()))


def _replace(target: Path, write: Callable[[BinaryIO], object]) -> None:
    fd, tmp = tempfile.mkstemp(prefix=f".{target.name}.", suffix=".tmp", dir=target.parent)
    try:
        with os.fdopen(fd, "wb") as f:
            write(f)
        os.replace(tmp, target)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise
