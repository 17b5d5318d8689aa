"""Network weights stored as an ``.npz`` with a ``.json`` of metadata beside it: reading the metadata, and the error
a corrupt or mismatched file raises.

Each save marks both files with one new random ``save_id`` (an array of the ``.npz``, a field of the ``.json``) and
writes the ``.json`` first: a save killed between the two files leaves a pair whose marks differ, which
:func:`read_arrays` refuses instead of loading one network's arrays with another's metadata."""

from __future__ import annotations

import json
import os
import uuid
from pathlib import Path
from typing import Any

import numpy as np

from lookalike._files import replace_file, write_bytes

SAVE_ID = "save_id"
"""The array of the ``.npz`` and the field of the ``.json`` that mark the two files of one save."""


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


def read_arrays(path: Path, meta_path: Path, meta: dict[str, Any]) -> dict[str, np.ndarray]:
    """The arrays of the weights ``path`` whose metadata ``meta`` was read from ``meta_path`` (the ``save_id`` mark
    left out); :class:`CheckpointError` when the file cannot be read or the two files are not of one save."""
    try:
        with np.load(path) as data:
            arrays = {k: data[k] for k in data.files}
    except (OSError, ValueError) as exc:
        raise CheckpointError(f"{path}: cannot read the weights ({exc})") from None
    mark = arrays.pop(SAVE_ID, None)
    wanted = meta.get(SAVE_ID)
    if wanted is not None and (mark is None or str(mark) != str(wanted)):
        raise CheckpointError(f"{path} and {meta_path} are not one pair: they were written by different saves (one "
                              "interrupted between the two files?); save or copy both files again")
    return arrays


def write_weights(path: Path, arrays: dict[str, Any], meta: dict[str, Any], *, compressed: bool = False) -> None:
    """Write ``path`` (``.npz``) and its ``.json`` metadata, both marked with a new ``save_id``, each through a unique
    temporary file in the same folder renamed into place, the ``.json`` first (a killed run leaves no temporary
    behind, and either the old pair, the new pair or a pair that :func:`read_arrays` refuses)."""
    save_id = uuid.uuid4().hex
    save = np.savez_compressed if compressed else np.savez
    text = json.dumps({**meta, SAVE_ID: save_id}, indent=2, sort_keys=True) + "\n"
    write_bytes(path.with_suffix(".json"), text.encode())
    marked: dict[str, Any] = {**arrays, SAVE_ID: np.array(save_id)}
    replace_file(path, lambda f: save(f, **marked))


def copy_weights(source: Path, target: Path) -> Path:
    """Copy the weights ``source`` (``.npz``) and its ``.json`` onto ``target`` (``.npz``) as :func:`write_weights`
    writes them: the ``.json`` first, each file through a temporary file renamed into place; returns ``target``."""
    for suffix in (".json", ".npz"):
        write_bytes(target.with_suffix(suffix), source.with_suffix(suffix).read_bytes())
    return target
