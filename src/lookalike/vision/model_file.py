"""Versioned model files: a JSON header (format name, version, settings) plus numpy arrays in one
``.npz``, written and read without pickle."""

from __future__ import annotations

import json
import zipfile
from pathlib import Path
from typing import Any

import numpy as np

from lookalike._files import replace_file


def save_model_file(path: str | Path, fmt: str, version: int, header: dict[str, Any],
                    arrays: dict[str, np.ndarray]) -> Path:
    """Write ``header`` (plus ``format`` and ``version``) and ``arrays`` to ``path``, through a temporary file
    renamed into place (an interrupted save leaves the earlier file whole)."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    full = {"format": fmt, "version": version, **header}
    payload: dict[str, Any] = {"header": np.array(json.dumps(full)), **arrays}
    replace_file(path, lambda fh: np.savez_compressed(fh, **payload))
    return path


def load_model_file(
    path: str | Path, fmt: str, version: int, what: str
) -> tuple[dict[str, Any], dict[str, np.ndarray]]:
    """The header and arrays of a :func:`save_model_file` file; ``ValueError`` when unreadable, of another format
    (``what`` names the expected kind) or version."""
    if Path(path).is_file() and not zipfile.is_zipfile(path):  # (numpy would say to trust it and unpickle it)
        raise ValueError(f"{path}: not a readable {what} (not an .npz archive)")
    try:
        with np.load(path, allow_pickle=False) as data:
            header = json.loads(str(data["header"]))
            arrays = {k: data[k] for k in data.files if k != "header"}
    except (OSError, ValueError, KeyError, EOFError, json.JSONDecodeError) as exc:
        raise ValueError(f"{path}: not a readable {what} ({exc})") from None
    found = header.get("format") if isinstance(header, dict) else None
    if found != fmt:
        raise ValueError(f"{path}: not a {what} (format {found!r})")
    if header.get("version") != version:
        raise ValueError(f"{path}: model version {header.get('version')} but this lookalike reads version {version}")
    return header, arrays
