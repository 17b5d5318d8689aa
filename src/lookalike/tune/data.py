"""Labelled data to tune on: the bench datasets by name, or MOTChallenge sequence folders (the one place
:mod:`lookalike.tune` reaches into :mod:`lookalike.bench`)."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import Any

from lookalike.bench.datasets import DATASETS, RealSequence, load_boxes, load_datasets
from lookalike.bench.runner import Entry, score_rows, track_rows


def sequence_key(seq: RealSequence) -> str:
    """``dataset/name``: how a sequence is named in parameter files and reports."""
    return f"{seq.dataset}/{seq.name}"


def load_tuning_data(items: Sequence[str], data_root: Path | None = None) -> list[RealSequence]:
    """Sequences from ``items``: bench dataset names (under ``data_root``) or MOTChallenge sequence folders (the
    dataset named after the folder); ``ValueError``/``FileNotFoundError`` saying what is missing."""
    out: list[RealSequence] = []
    for item in items:
        path = Path(item)
        if path.exists():
            if not path.is_dir():
                raise ValueError(f"{item}: expected a MOTChallenge sequence folder (gt/gt.txt, det/det.txt) "
                                 "or a folder of them")
            out += load_boxes(path, path.resolve().name)
        elif item in DATASETS:
            if data_root is None:
                raise ValueError(f"{item}: a bench dataset needs the data folder (--data)")
            out += load_datasets(data_root, [item])
        else:
            raise ValueError(f"{item}: no such folder; neither a folder nor a bench dataset ({', '.join(DATASETS)})")
    keys = [sequence_key(s) for s in out]
    dupes = sorted({k for k in keys if keys.count(k) > 1})
    if dupes:
        raise ValueError(f"sequences given twice: {', '.join(dupes)}")
    if not out:
        raise ValueError("no sequence to tune on")
    empty = [sequence_key(s) for s in out if s.gt is not None and len(s.gt) == 0
             or s.gt_points is not None and len(s.gt_points[0]) == 0]
    if len(empty) == len(out):
        raise ValueError(f"no ground truth to tune on: the ground truth of {', '.join(empty)} is empty")
    return out


def score_params(tracker: str, params: dict[str, Any], seq: RealSequence) -> dict[str, float]:
    """Scores (combinable counts and metrics) of ``tracker`` with exactly ``params`` (no bench preset) on ``seq``."""
    return score_rows(seq, track_rows(Entry(tracker, tracker, params=dict(params)), seq))


__all__ = ["RealSequence", "load_tuning_data", "score_params", "sequence_key"]
