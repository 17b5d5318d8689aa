"""``lookalike eval``: score result folders against MOTChallenge ground truth."""

from __future__ import annotations

import csv
import json
import os
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path
from typing import Optional, Sequence

import typer
from rich import box
from rich.table import Table

from lookalike.cli.app import app, console, fail
from lookalike.eval import BENCHMARKS, METRICS, combine, evaluate_sequence
from lookalike.io import MotSequence, find_sequences, read_mot

COMBINED = "COMBINED"

HEADLINE = {
    "HOTA": ("HOTA", "DetA", "AssA"),
    "CLEAR": ("MOTA", "MOTP", "IDSW", "Frag", "CLR_FP", "CLR_FN"),
    "Identity": ("IDF1",),
}
SHORT = {"CLR_FP": "FP", "CLR_FN": "FN"}
PERCENT = {"HOTA", "DetA", "AssA", "LocA", "MOTA", "MOTP", "IDF1", "IDP", "IDR"}


def _cell(key: str, value: float) -> str:
    return f"{100 * value:.2f}" if key in PERCENT else f"{value:g}"


def _columns(metrics: list[str]) -> list[str]:
    return [k for m in ("HOTA", "CLEAR", "Identity") if m in metrics for k in HEADLINE[m]]


def _result_file(results: Path, name: str) -> Path:
    for candidate in (results / f"{name}.txt", results / "data" / f"{name}.txt"):
        if candidate.is_file():
            return candidate
    raise ValueError(f"{results}: no result file for sequence {name} (expected {results / (name + '.txt')})")


def _score(job: tuple[MotSequence, Path, str, tuple[str, ...], float]) -> dict[str, float]:
    seq, res_path, benchmark, metrics, threshold = job
    return evaluate_sequence(read_mot(seq.gt_path), read_mot(res_path), iou_threshold=threshold,
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


@app.command("eval")
def eval_command(
    gt: Path = typer.Option(..., "--gt", help="Ground-truth root: sequence folders with gt/gt.txt."),
    results: list[Path] = typer.Option(..., "--results", help="Folder of <sequence>.txt results (repeat to compare trackers)."),
    benchmark: str = typer.Option("MOT15", help=f"Ground-truth rules: {', '.join(BENCHMARKS)}."),
    metrics: Optional[list[str]] = typer.Option(None, "--metrics", help=f"Any of {', '.join(METRICS)} (repeatable; default all)."),
    iou_threshold: float = typer.Option(0.5, help="IoU a CLEAR/identity match needs."),
    workers: int = typer.Option(1, help="Processes scoring sequences in parallel."),
    json_path: Optional[Path] = typer.Option(None, "--json", help="Write every value as JSON here."),
    csv_path: Optional[Path] = typer.Option(None, "--csv", help="Write every value as CSV here (one row per tracker and sequence)."),
) -> None:
    """Score trackers with HOTA, CLEAR MOT and identity metrics (values shown in %)."""
    chosen = [next((m for m in METRICS if m.lower() == x.lower()), x) for x in (metrics or METRICS)]
    names = [p.name or str(p) for p in results]
    if len(set(names)) != len(names):
        names = [str(p) for p in results]
    scores: dict[str, dict[str, dict[str, float]]] = {}
    for name, folder in zip(names, results):
        try:
            scores[name] = evaluate_folders(gt, folder, benchmark=benchmark, metrics=chosen,
                                            iou_threshold=iou_threshold, workers=workers)
        except (FileNotFoundError, ValueError) as exc:
            fail(str(exc))
    columns = _columns(chosen)
    if len(scores) == 1:
        name, per_seq = next(iter(scores.items()))
        table = _table(f"{name} ({benchmark})", "sequence", columns)
        for seq, values in per_seq.items():
            style = "bold" if seq == COMBINED else None
            table.add_row(seq, *[_cell(c, values[c]) for c in columns], style=style)
    else:
        table = _table(f"trackers, combined over sequences ({benchmark})", "tracker", columns)
        for name, per_seq in scores.items():
            table.add_row(name, *[_cell(c, per_seq[COMBINED][c]) for c in columns])
    console.print(table)
    if json_path is not None:
        json_path.parent.mkdir(parents=True, exist_ok=True)
        json_path.write_text(json.dumps(scores, indent=1))
    if csv_path is not None:
        _write_csv(csv_path, scores)


def _table(title: str, first: str, columns: list[str]) -> Table:
    table = Table(title=title, box=box.SIMPLE_HEAD, show_edge=False, pad_edge=False,
                  padding=(0, 1), collapse_padding=True)
    table.add_column(first, no_wrap=True)
    for c in columns:
        table.add_column(SHORT.get(c, c), justify="right", no_wrap=True)
    return table


def _write_csv(path: Path, scores: dict[str, dict[str, dict[str, float]]]) -> None:
    keys = list(next(iter(next(iter(scores.values())).values())).keys())
    path.parent.mkdir(parents=True, exist_ok=True)
    with open(path, "w", newline="") as fh:
        writer = csv.writer(fh)
        writer.writerow(["tracker", "seq", *keys])
        for tracker, per_seq in scores.items():
            for seq, values in per_seq.items():
                writer.writerow([tracker, seq, *[repr(values.get(k, "")) for k in keys]])
