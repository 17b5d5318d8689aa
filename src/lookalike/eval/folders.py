"""Scoring folders of MOTChallenge results against ground-truth sequence folders (``lookalike eval``)."""

from __future__ import annotations

import os
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING

from lookalike.eval import METRICS, combine, evaluate_sequence
from lookalike.io import MotSequence, find_sequences, read_mot

if TYPE_CHECKING:
    from lookalike.io.results import Results

COMBINED = "COMBINED"


def _result_file(results: Path, name: str) -> Path:
    for candidate in (results / f"{name}.txt", results / "data" / f"{name}.txt"):
        if candidate.is_file():
            return candidate
    raise ValueError(f"{results}: no result file for sequence {name} (expected {results / (name + '.txt')})")


def _score(job: tuple[MotSequence, Path, str, tuple[str, ...], float]) -> dict[str, float]:
    seq, res_path, benchmark, metrics, threshold = job
    assert seq.gt_path is not None  # only sequences with ground truth are scored
    return evaluate_sequence(read_mot(seq.gt_path), read_mot(res_path), iou_threshold=threshold,
                             benchmark=benchmark, metrics=metrics, num_frames=seq.length)


def evaluate_folders(gt_root: str | os.PathLike[str], results: str | os.PathLike[str], *, benchmark: str = "MOT15",
                     metrics: Sequence[str] = METRICS, iou_threshold: float = 0.5,
                     workers: int = 1) -> dict[str, dict[str, float]]:
    """Per-sequence results (name -> metrics) and their combination under ``"COMBINED"``; every ground-truth sequence
    needs a result file; ``workers`` processes."""
    if workers < 1:
        raise ValueError(f"workers must be >= 1, got {workers}")
    if Path(gt_root).is_file():
        raise ValueError(f"{gt_root}: is a file; give the sequence folder that holds gt/gt.txt, or a folder of them")
    sequences = [s for s in find_sequences(gt_root) if s.gt_path is not None]
    if not sequences:
        raise ValueError(f"{gt_root}: no sequence with gt/gt.txt")
    results = Path(results)
    if results.is_file():
        raise ValueError(f"{results}: is a file; give the folder that holds a <sequence>.txt for each sequence of "
                         f"{gt_root} ({sequences[0].name}.txt, ...)")
    if not results.is_dir():
        raise ValueError(f"{results}: results folder not found")
    jobs = [(s, _result_file(results, s.name), benchmark, tuple(metrics), iou_threshold) for s in sequences]
    if workers > 1 and len(jobs) > 1:
        from concurrent.futures import ProcessPoolExecutor  # imported when used: a short start-up

        with ProcessPoolExecutor(max_workers=min(workers, len(jobs))) as pool:
            scored = list(pool.map(_score, jobs))
    else:
        scored = [_score(j) for j in jobs]
    out = {s.name: r for s, r in zip(sequences, scored)}
    out[COMBINED] = combine(scored)
    return out


def folder_results(scores: dict[str, dict[str, dict[str, float]]], gt_root: str | os.PathLike[str],
                   command: str = "", options: dict[str, object] | None = None) -> Results:
    """``{tracker: {sequence: metrics}}`` of :func:`evaluate_folders` as a results document: table ``scores``, one
    row per tracker and sequence and a combined one, metrics under :func:`~lookalike.io.results.metric_key`."""
    from lookalike.io.results import Results, metric_key  # imported when used: a short start-up

    dataset = Path(gt_root).name or str(gt_root)
    seqs = {s for per in scores.values() for s in per if s != COMBINED}
    first = next(iter(scores.values()), {})
    frames = sum(int(values.get("CLR_Frames", 0)) for seq, values in first.items() if seq != COMBINED)
    if not seqs and first:
        frames = int(first.get(COMBINED, {}).get("CLR_Frames", 0))
    doc = Results("eval", command=command, sequences=max(len(seqs), 1 if first else 0), frames=frames,
                  options=dict(options or {}))
    for tracker, per_seq in scores.items():
        for seq, values in per_seq.items():
            combined = seq == COMBINED
            doc.add("scores", dataset=dataset, sequence=None if combined else seq, tracker=tracker,
                    combined=combined, metrics={metric_key(k): v for k, v in values.items()})
    return doc


__all__ = ["COMBINED", "evaluate_folders", "folder_results"]
