"""The leaderboard of ``lookalike bench real``: per dataset, entries by mean rank on HOTA, IDF1 and MOTA combined over
sequences (ties: IDF1); the combined ranking by mean rank over datasets (more datasets first); plots."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from lookalike.bench.datasets import RealSequence
from lookalike.bench.progress import ProgressFactory, no_progress
from lookalike.bench.runner import Entry, job_pairs, run_jobs
from lookalike.bench.tables import pyplot
from lookalike.eval import combine
from lookalike.io.outputs import atomic_path
from lookalike.io.results import Results

COLUMNS = ("Dataset", "Tracker", "HOTA", "IDF1", "MOTA", "IDSW", "Frames/s", "Rank")
METRICS = ("HOTA", "IDF1", "MOTA")


def ranks(values: np.ndarray) -> np.ndarray:
    """1 for the largest value; NaN ranks last (ties in order of appearance)."""
    v = np.where(np.isfinite(values), values, -np.inf)
    order = np.argsort(-v, kind="stable")
    out = np.empty(len(v))
    out[order] = np.arange(1, len(v) + 1)
    return out


def _percent(scores: dict[str, float]) -> dict[str, Any]:
    return {"HOTA": round(100 * scores["HOTA"], 2), "IDF1": round(100 * scores["IDF1"], 2),
            "MOTA": round(100 * scores["MOTA"], 2), "IDSW": int(scores["IDSW"])}


def sequence_rows(pairs: Sequence[tuple[Entry, RealSequence]],
                  results: Sequence[dict[str, Any]]) -> list[dict[str, Any]]:
    """One row per job: dataset, sequence, tracker and its scores in % (or its error)."""
    out = []
    for (e, seq), r in zip(pairs, results):
        row: dict[str, Any] = {"Dataset": seq.dataset, "Sequence": seq.name, "Tracker": e.label}
        row.update({"Error": r["error"]} if "error" in r else _percent(r["scores"]))
        out.append(row)
    return out


def dataset_row(dataset: str, label: str, runs: list[dict[str, Any]]) -> dict[str, Any]:
    """One entry's row on one dataset from its job results: combined scores and frames/s."""
    row: dict[str, Any] = {"Dataset": dataset, "Tracker": label}
    errors = [r["error"] for r in runs if "error" in r]
    if errors:
        row.update({"HOTA": float("nan"), "IDF1": float("nan"), "MOTA": float("nan"), "IDSW": -1,
                    "Frames/s": float("nan"), "Error": errors[0]})
        return row
    seconds = sum(r["seconds"] for r in runs)
    row.update(_percent(combine([r["scores"] for r in runs])))
    row["Frames/s"] = round(sum(r["frames"] for r in runs) / seconds, 1) if seconds > 0 else float("inf")
    return row


def rank_rows(rows: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """``rows`` of one dataset with ``Rank`` set, best first (mean rank over HOTA, IDF1, MOTA; ties: IDF1)."""
    metric_ranks = np.mean([ranks(np.array([r[m] for r in rows], float)) for m in METRICS], axis=0)
    idf1 = np.array([r["IDF1"] for r in rows], float)
    order = np.lexsort((-np.nan_to_num(idf1, nan=-1.0), metric_ranks))
    for rank, i in enumerate(order, start=1):
        rows[i]["Rank"] = rank
    return [rows[i] for i in order]


def combined_ranking(table: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """Entries ordered by their mean rank over the datasets they ran on (more datasets first)."""
    combined = []
    for label in dict.fromkeys(r["Tracker"] for r in table):
        rk = [r["Rank"] for r in table if r["Tracker"] == label]
        combined.append({"Tracker": label, "Mean rank": round(float(np.mean(rk)), 2), "Datasets": len(rk)})
    combined.sort(key=lambda r: (-r["Datasets"], r["Mean rank"]))
    for k, r in enumerate(combined, start=1):
        r["Rank"] = k
    return combined


def leaderboard(entries: Sequence[Entry], sequences: Sequence[RealSequence], results: Sequence[dict[str, Any]]
                ) -> tuple[list[dict[str, Any]], list[dict[str, Any]], list[dict[str, Any]]]:
    """``(dataset rows, combined ranking, per-sequence rows)`` from :func:`~lookalike.bench.runner.run_jobs`."""
    pairs = job_pairs(entries, sequences)
    if len(pairs) != len(results):
        raise ValueError(f"results: expected {len(pairs)} job results, got {len(results)}")
    grouped: dict[tuple[str, str], list[dict[str, Any]]] = {}
    for (e, seq), r in zip(pairs, results):
        grouped.setdefault((seq.dataset, e.label), []).append(r)
    table: list[dict[str, Any]] = []
    for dataset in dict.fromkeys(s.dataset for s in sequences):
        rows = [dataset_row(dataset, e.label, grouped[(dataset, e.label)]) for e in entries
                if grouped.get((dataset, e.label))]
        table += rank_rows(rows)
    return table, combined_ranking(table), sequence_rows(pairs, results)


def run_with_progress(entries: Sequence[Entry], sequences: Sequence[RealSequence], *, workers: int = 1,
                      backend: str = "local", address: str | None = None,
                      progress: ProgressFactory = no_progress) -> list[dict[str, Any]]:
    """:func:`~lookalike.bench.runner.run_jobs`, one sequence at a time locally (``progress`` per sequence)."""
    if backend != "local" or len(sequences) < 2:
        step = progress("bench real", 1)
        results = run_jobs(entries, sequences, workers=workers, backend=backend, address=address)
        step()
        return results
    step = progress("bench real", len(sequences))
    results = []
    for seq in sequences:  # job_pairs is sequence-major: the concatenation keeps its order
        results += run_jobs(entries, [seq], workers=workers, backend=backend, address=address)
        step()
    return results


def _metrics(row: dict[str, Any]) -> dict[str, Any]:
    out: dict[str, Any] = {k.lower(): row[k] / 100 for k in METRICS if k in row}
    if "IDSW" in row and row["IDSW"] >= 0:
        out["idsw"] = int(row["IDSW"])
    if "Frames/s" in row:
        out["frames_per_s"] = row["Frames/s"]
    if "Rank" in row:
        out["rank"] = row["Rank"]
    return out


def leaderboard_results(part: str, rows: list[dict[str, Any]], combined: list[dict[str, Any]],
                        per_seq: list[dict[str, Any]], skipped: dict[str, str | None],
                        sequences: Sequence[RealSequence], command: str = "",
                        options: dict[str, Any] | None = None) -> Results:
    """The leaderboard as a results document: tables ``datasets`` (combined, with ``rank``), ``sequences`` and
    ``ranking`` (``mean_rank`` over ``datasets``)."""
    doc = Results("bench real", command=command, sequences=len(sequences),
                  frames=sum(s.length for s in sequences), options={"part": part, **(options or {})},
                  notes={"skipped_peers": {k: v for k, v in skipped.items() if v}})
    for r in rows:
        doc.add("datasets", dataset=r["Dataset"], tracker=r["Tracker"], combined=True,
                metrics={} if "Error" in r else _metrics(r), error=r.get("Error"))
    for r in per_seq:
        doc.add("sequences", dataset=r["Dataset"], sequence=r["Sequence"], tracker=r["Tracker"],
                metrics={} if "Error" in r else _metrics(r), error=r.get("Error"))
    for r in combined:
        doc.add("ranking", dataset=None, tracker=r["Tracker"], combined=True,
                metrics={"rank": r["Rank"], "mean_rank": r["Mean rank"], "datasets": r["Datasets"]})
    return doc


def plot_leaderboard(rows: list[dict[str, Any]], folder: Path) -> list[Path]:
    """One bar chart per dataset (HOTA, IDF1, MOTA per tracker) as PNG files in ``folder``."""
    plt = pyplot()
    folder.mkdir(parents=True, exist_ok=True)
    paths = []
    for dataset in dict.fromkeys(r["Dataset"] for r in rows):
        sub = [r for r in rows if r["Dataset"] == dataset]
        x = np.arange(len(sub))
        fig, ax = plt.subplots(figsize=(max(6.0, 0.9 * len(sub)), 4))
        for k, metric in enumerate(METRICS):
            ax.bar(x + (k - 1) * 0.27, [r[metric] for r in sub], width=0.27, label=metric)
        ax.set_xticks(x, [r["Tracker"] for r in sub], rotation=30, ha="right")
        ax.set_ylabel("%")
        ax.set_title(f"{dataset}: identical detections (ordered by rank)", pad=22)
        ax.legend(ncol=3, loc="lower center", bbox_to_anchor=(0.5, 1.0), frameon=False, fontsize=9)
        ax.grid(axis="y", alpha=0.3)
        fig.tight_layout()
        path = folder / f"bench_real_{dataset}.png"
        with atomic_path(path) as tmp:
            fig.savefig(tmp, dpi=110, format="png")
        plt.close(fig)
        paths.append(path)
    return paths


__all__ = ["COLUMNS", "METRICS", "combined_ranking", "dataset_row", "leaderboard", "leaderboard_results",
           "plot_leaderboard", "rank_rows", "ranks", "run_with_progress", "sequence_rows"]
