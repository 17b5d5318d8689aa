"""Bench tables as files: rows (dicts) written as JSON and/or CSV, and matplotlib for their charts."""

from __future__ import annotations

import csv
import json
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from lookalike._optional import needs
from lookalike.io.outputs import atomic_path, write_atomic


def pyplot() -> Any:
    """``matplotlib.pyplot`` on the file-only Agg backend (``matplotlib`` needed)."""
    with needs("matplotlib"):
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    return plt


def write_rows(rows: list[dict[str, Any]], json_path: Path | None, csv_path: Path | None,
               columns: Sequence[str] | None = None) -> None:
    """Write rows as JSON and/or CSV (``columns``: default the first row's keys; missing cells empty)."""
    if json_path is not None:
        write_atomic(json_path, json.dumps(rows, indent=2) + "\n")
    if csv_path is not None and rows:
        with atomic_path(csv_path) as tmp, tmp.open("w", newline="") as fh:
            writer = csv.DictWriter(fh, fieldnames=list(columns or rows[0]), restval="")
            writer.writeheader()
            writer.writerows(rows)


__all__ = ["pyplot", "write_rows"]
