"""Scoring folders: a ground-truth root of MOTChallenge sequences against a results folder
holding one ``<sequence>.txt`` per sequence (TrackEval's layout)."""

from __future__ import annotations

import os
import warnings
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path
from typing import Sequence

import numpy as np

from lookalike.eval.api import METRICS, combine, evaluate_sequence
from lookalike.io.motchallenge import MotTable, read_mot
from lookalike.io.sequences import MotSequence, find_sequences

COMBINED = "COMBINED"


def _result_file(results: Path, name: str) -> Path:
    for candidate in (results / f"{name}.txt", results / "data" / f"{name}.txt"):
        if candidate.is_file():
            return candidate
    raise ValueError(f"{results}: no result file for sequence {name} (expected {results / (name + '.txt')})")


def read_table(path: str | os.PathLike[str]) -> MotTable:
    """:func:`lookalike.io.read_mot` with numpy's C parser as a fast path for regular files
    (about 10x faster on MOT17 ground truth); anything irregular or invalid is read by
    ``read_mot`` itself, so errors name the file and line as usual."""
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            data = np.loadtxt(path, delimiter=",", ndmin=2)
    except (ValueError, OSError):
        return read_mot(path)
    if data.shape[0] == 0 or data.shape[1] < 7:
        return read_mot(path)
    valid = np.isfinite(data[:, :6]).all() and (data[:, 4:6] >= 0).all() and (data[:, 0] >= 1).all()
    if not valid:
        return read_mot(path)
    return MotTable(frame=data[:, 0].astype(int), track_id=data[:, 1].astype(int), xywh=data[:, 2:6].copy(),
                    conf=data[:, 6].copy(), extra=data[:, 7:].copy(), path=Path(path))


def _score(job: tuple[MotSequence, Path, str, tuple[str, ...], float]) -> dict[str, float]:
    seq, res_path, benchmark, metrics, threshold = job
    return evaluate_sequence(read_table(seq.gt_path), read_table(res_path), iou_threshold=threshold,
                             benchmark=benchmark, metrics=metrics, num_frames=seq.length)


def evaluate_folders(
    gt_root: str | os.PathLike[str],
    results: str | os.PathLike[str],
    *,
    benchmark: str = "MOT15",
    metrics: Sequence[str] = METRICS,
    iou_threshold: float = 0.5,
    workers: int = 1,
) -> dict[str, dict[str, float]]:
    """Per-sequence results (sequence name -> metrics) and their combination under ``"COMBINED"``.

    Every ground-truth sequence needs a result file; sequence lengths come from ``seqinfo.ini``
    (else the last frame present). ``workers > 1`` scores sequences in that many processes.
    """
    if workers < 1:
        raise ValueError(f"workers must be >= 1, got {workers}")
    sequences = [s for s in find_sequences(gt_root) if s.gt_path is not None]
    if not sequences:
        raise ValueError(f"{gt_root}: no sequence with gt/gt.txt")
    results = Path(results)
    if not results.is_dir():
        raise ValueError(f"{results}: results folder not found")
    jobs = [(s, _result_file(results, s.name), benchmark, tuple(metrics), iou_threshold) for s in sequences]
    if workers > 1 and len(jobs) > 1:
        with ProcessPoolExecutor(max_workers=min(workers, len(jobs))) as pool:
            scored = list(pool.map(_score, jobs))
    else:
        scored = [_score(j) for j in jobs]
    out = {s.name: r for s, r in zip(sequences, scored)}
    out[COMBINED] = combine(scored)
    return out
