"""``lookalike bench real``: a leaderboard on real data, lookalike's box trackers against the peers.

Datasets (``--data``, default ``../shared/data`` next to the repository): the 7 MOT15 training
sequences with their Faster R-CNN detections, the pigs (23 identical animals; boxes), the HexBug
clips (blob detector, head points), and ``mot17-synth``: the 7 MOT17 ground truths seen through a
synthetic detector (the project's noise model; a set nothing was tuned on, not a real detector;
``mot17-synth2``, ``mot17-synth3``: the same with other noise seeds). Every entry runs on identical detections; peers that
are not installed are listed as skipped. Per dataset the table gives HOTA, IDF1, MOTA (combined over the
sequences as TrackEval does), IDSW, frames/s (tracking only) and a rank: entries are ordered by the
mean of their ranks on HOTA, IDF1 and MOTA (ties: IDF1). ``--part first|second`` scores the first
or second half of every sequence instead (boxtrack's parameters were chosen on first halves, so the
second halves are unseen by that choice). The combined ranking orders entries by
their mean rank over the datasets. ``--workers N`` runs jobs in N processes; ``--backend ray`` runs
them as Ray tasks (``--address`` of a cluster, else a local ``ray.init()``); tables are identical.
"""

from __future__ import annotations

import csv
import json
from pathlib import Path
from typing import Any

import numpy as np
import typer
from rich.table import Table

from lookalike.cli.app import console, fail
from lookalike.cli.bench import bench_app
from lookalike.cli.bench_peers import PEERS, peer_status
from lookalike.cli.bench_real_data import (
    DATASETS,
    PARTS,
    SYNTH_SEEDS,
    RealSequence,
    cut_sequence,
    detect_hexbug,
    hexbug_clips,
    load_boxes,
    load_mot17_synth,
)
from lookalike.cli.bench_real_run import Entry, job_pairs, map_jobs, run_jobs
from lookalike.eval import combine
from lookalike.parallel import BACKENDS

DEFAULT_DATA = Path(__file__).resolve().parents[3].parent / "shared" / "data"
BOX_TRACKERS = ("sort", "boxtrack")  # lookalike trackers that need nothing but boxes and scores
COLUMNS = ("Dataset", "Tracker", "HOTA", "IDF1", "MOTA", "IDSW", "Frames/s", "Rank")


def load_datasets(root: Path, datasets: list[str], *, sequences: list[str] | None = None,
                  max_clips: int | None = None, workers: int = 1, backend: str = "local",
                  address: str | None = None) -> list[RealSequence]:
    """The sequences of ``datasets`` under ``root`` (HexBug detection runs on the chosen backend)."""
    out: list[RealSequence] = []
    for name in datasets:
        if name not in DATASETS:
            raise ValueError(f"datasets: unknown dataset {name!r}; known: {', '.join(DATASETS)}")
        folder = root / "mot17" / "gt" if name in SYNTH_SEEDS else root / name
        if not folder.is_dir():
            raise FileNotFoundError(f"{folder}: dataset folder not found (set --data)")
        if name in SYNTH_SEEDS:
            out += [s for s in load_mot17_synth(folder, SYNTH_SEEDS[name], name) if not sequences or s.name in sequences
                    or name in sequences]
        elif name == "hexbug":
            clips = [c for c in hexbug_clips(folder) if not sequences or c.stem in sequences][:max_clips]
            out += map_jobs(detect_hexbug, clips, workers=workers, backend=backend, address=address)
        else:
            out += [s for s in load_boxes(folder, name) if not sequences or s.name in sequences
                    or name in sequences]
    if not out:
        raise ValueError("no sequence selected")
    return out


def default_entries(trackers: list[str], peers: list[str], closed_set: bool = True) -> list[Entry]:
    """lookalike trackers and peers; with ``boxtrack`` also ``boxtrack-global`` (without the
    per-sequence parameters, where there are some), ``boxtrack-offline`` (its result post-processed
    offline, :mod:`lookalike.trackers.offline`) and ``boxtrack-closed`` (where the count is known)."""
    entries = [Entry(t, t) for t in trackers]
    if "boxtrack" in trackers:
        entries += [Entry("boxtrack-global", "boxtrack", per_sequence=False, only_where_tuned=True),
                    Entry("boxtrack-offline", "boxtrack", offline=True)]
    if closed_set and "boxtrack" in trackers:
        entries.append(Entry("boxtrack-closed", "boxtrack", closed_set=True))
    return entries + [Entry(p, p, kind="peer") for p in peers]


def _ranks(values: np.ndarray) -> np.ndarray:
    """1 for the largest value; NaN ranks last."""
    v = np.where(np.isfinite(values), values, -np.inf)
    order = np.argsort(-v, kind="stable")
    ranks = np.empty(len(v))
    ranks[order] = np.arange(1, len(v) + 1)
    return ranks


def leaderboard(entries: list[Entry], sequences: list[RealSequence],
                results: list[dict[str, Any]]) -> tuple[list[dict[str, Any]], list[dict[str, Any]], list[dict[str, Any]]]:
    """``(dataset rows, combined ranking rows, per-sequence rows)`` from :func:`run_jobs` results."""
    per_seq, table = [], []
    pairs = job_pairs(entries, sequences)
    if len(pairs) != len(results):
        raise ValueError(f"results: expected {len(pairs)} job results, got {len(results)}")
    grouped: dict[tuple[str, str], list[tuple[RealSequence, dict[str, Any]]]] = {}
    for (e, seq), r in zip(pairs, results):
        grouped.setdefault((seq.dataset, e.label), []).append((seq, r))
        row = {"Dataset": seq.dataset, "Sequence": seq.name, "Tracker": e.label}
        if "error" in r:
            row["Error"] = r["error"]
        else:
            s = r["scores"]
            row.update({"HOTA": round(100 * s["HOTA"], 2), "IDF1": round(100 * s["IDF1"], 2),
                        "MOTA": round(100 * s["MOTA"], 2), "IDSW": int(s["IDSW"])})
        per_seq.append(row)
    for dataset in dict.fromkeys(s.dataset for s in sequences):
        rows = []
        for e in entries:
            runs = grouped.get((dataset, e.label))
            if not runs:
                continue
            errors = [r["error"] for _, r in runs if "error" in r]
            row: dict[str, Any] = {"Dataset": dataset, "Tracker": e.label}
            if errors:
                row.update({"HOTA": float("nan"), "IDF1": float("nan"), "MOTA": float("nan"), "IDSW": -1,
                            "Frames/s": float("nan"), "Error": errors[0]})
            else:
                c = combine([r["scores"] for _, r in runs])
                seconds = sum(r["seconds"] for _, r in runs)
                row.update({"HOTA": round(100 * c["HOTA"], 2), "IDF1": round(100 * c["IDF1"], 2),
                            "MOTA": round(100 * c["MOTA"], 2), "IDSW": int(c["IDSW"]),
                            "Frames/s": round(sum(r["frames"] for _, r in runs) / seconds, 1) if seconds > 0 else float("inf")})
            rows.append(row)
        metric_ranks = np.mean([_ranks(np.array([r[m] for r in rows], float)) for m in ("HOTA", "IDF1", "MOTA")], axis=0)
        idf1 = np.array([r["IDF1"] for r in rows], float)
        order = np.lexsort((-np.nan_to_num(idf1, nan=-1.0), metric_ranks))
        for rank, i in enumerate(order, start=1):
            rows[i]["Rank"] = rank
        table += [rows[i] for i in order]
    combined = []
    for label in dict.fromkeys(r["Tracker"] for r in table):
        ranks = [r["Rank"] for r in table if r["Tracker"] == label]
        combined.append({"Tracker": label, "Mean rank": round(float(np.mean(ranks)), 2), "Datasets": len(ranks)})
    combined.sort(key=lambda r: (-r["Datasets"], r["Mean rank"]))
    for k, r in enumerate(combined, start=1):
        r["Rank"] = k
    return table, combined, per_seq


def plot_leaderboard(rows: list[dict[str, Any]], folder: Path) -> list[Path]:
    """One bar chart per dataset (HOTA, IDF1, MOTA per tracker) as PNG files in ``folder``."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    folder.mkdir(parents=True, exist_ok=True)
    paths = []
    for dataset in dict.fromkeys(r["Dataset"] for r in rows):
        sub = [r for r in rows if r["Dataset"] == dataset]
        x = np.arange(len(sub))
        fig, ax = plt.subplots(figsize=(max(6.0, 0.9 * len(sub)), 4))
        for k, metric in enumerate(("HOTA", "IDF1", "MOTA")):
            ax.bar(x + (k - 1) * 0.27, [r[metric] for r in sub], width=0.27, label=metric)
        ax.set_xticks(x, [r["Tracker"] for r in sub], rotation=30, ha="right")
        ax.set_ylabel("%")
        ax.set_title(f"{dataset}: identical detections (ordered by rank)", pad=22)
        ax.legend(ncol=3, loc="lower center", bbox_to_anchor=(0.5, 1.0), frameon=False, fontsize=9)
        ax.grid(axis="y", alpha=0.3)
        fig.tight_layout()
        path = folder / f"bench_real_{dataset}.png"
        fig.savefig(path, dpi=110)
        plt.close(fig)
        paths.append(path)
    return paths


def _split(values: list[str] | None) -> list[str]:
    return [v.strip() for item in values or [] for v in item.split(",") if v.strip()]


def _cell(value: Any) -> str:
    if isinstance(value, float):
        return "–" if not np.isfinite(value) else f"{value:.2f}" if abs(value) < 1e4 else f"{value:,.0f}"
    return str(value)


@bench_app.command("real")
def real(
    data: Path = typer.Option(DEFAULT_DATA, "--data", help="Folder with mot15/, pigs/, hexbug/, mot17/."),
    datasets: list[str] = typer.Option(list(DATASETS[:3]), "--datasets",
                                       help=f"Datasets (comma-separated or repeated): {', '.join(DATASETS)}."),
    trackers: list[str] = typer.Option(list(BOX_TRACKERS), "--trackers", help="lookalike box trackers."),
    peers: list[str] = typer.Option(list(PEERS), "--peers", help="Peers to try ('none' for none); absent ones are skipped."),
    sequences: list[str] | None = typer.Option(None, "--sequences", help="Only these sequences/clips."),
    max_clips: int | None = typer.Option(None, "--max-clips", min=1, help="At most this many HexBug clips."),
    part: str = typer.Option("full", "--part", help="Score whole sequences ('full'), their first halves "
                             "(where boxtrack's parameters were chosen: 'first') or second halves ('second')."),
    workers: int = typer.Option(1, "--workers", min=1, help="Local processes (or Ray CPUs for a local Ray)."),
    backend: str = typer.Option("local", "--backend", help=f"One of {', '.join(BACKENDS)}."),
    address: str | None = typer.Option(None, "--address", help="Ray cluster address (default: a local ray.init())."),
    json_path: Path | None = typer.Option(None, "--json", help="Write tables as JSON."),
    csv_path: Path | None = typer.Option(None, "--csv", help="Write the dataset rows as CSV."),
    plots: Path | None = typer.Option(None, "--plots", help="Folder for one bar chart per dataset."),
) -> None:
    """Leaderboard on real data: HOTA, IDF1, MOTA, IDSW, frames/s and rank per dataset, and combined."""
    tracker_list, peer_list = _split(trackers), [p for p in _split(peers) if p != "none"]
    if part not in PARTS:
        fail(f"--part: expected one of {', '.join(PARTS)}, got {part!r}")
    if backend not in BACKENDS:
        fail(f"--backend: expected one of {', '.join(BACKENDS)}, got {backend!r}")
    for t in tracker_list:
        if t not in BOX_TRACKERS:
            fail(f"--trackers: {t!r} is not a box tracker; choose from {', '.join(BOX_TRACKERS)}")
    try:
        status = peer_status(peer_list)
        seqs = load_datasets(data, _split(datasets), sequences=_split(sequences) or None, max_clips=max_clips,
                             workers=workers, backend=backend, address=address)
    except (ValueError, FileNotFoundError) as exc:
        fail(str(exc))
    seqs = [cut_sequence(s, part) for s in seqs]
    for name, why in status.items():
        if why is not None:
            console.print(f"[yellow]skipped peer {name}: {why}[/yellow]")
    entries = default_entries(tracker_list, [p for p, why in status.items() if why is None])
    results = run_jobs(entries, seqs, workers=workers, backend=backend, address=address)
    rows, combined, per_seq = leaderboard(entries, seqs, results)
    for dataset in dict.fromkeys(r["Dataset"] for r in rows):
        n = sum(1 for s in seqs if s.dataset == dataset)
        what = "" if part == "full" else f" ({part} halves)"
        table = Table(title=f"{dataset}: {n} sequence(s){what}, identical detections")
        for c in COLUMNS[1:]:
            table.add_column(c, justify="left" if c == "Tracker" else "right")
        for r in (r for r in rows if r["Dataset"] == dataset):
            table.add_row(*(_cell(r[c]) for c in COLUMNS[1:]))
        console.print(table)
    table = Table(title="Combined ranking (mean rank over datasets)")
    for c in ("Rank", "Tracker", "Mean rank", "Datasets"):
        table.add_column(c, justify="left" if c == "Tracker" else "right")
    for r in combined:
        table.add_row(str(r["Rank"]), r["Tracker"], f"{r['Mean rank']:.2f}", str(r["Datasets"]))
    console.print(table)
    for r in rows:
        if "Error" in r:
            console.print(f"[red]{r['Dataset']} / {r['Tracker']} failed: {r['Error']}[/red]")
    if json_path is not None:
        json_path.parent.mkdir(parents=True, exist_ok=True)
        json_path.write_text(json.dumps({"part": part, "datasets": rows, "combined": combined, "sequences": per_seq,
                                         "skipped": {k: v for k, v in status.items() if v}}, indent=2) + "\n")
    if csv_path is not None:
        csv_path.parent.mkdir(parents=True, exist_ok=True)
        with csv_path.open("w", newline="") as fh:
            writer = csv.DictWriter(fh, fieldnames=[*COLUMNS, "Error"], restval="")
            writer.writeheader()
            writer.writerows(rows)
    if plots is not None:
        for p in plot_leaderboard([r for r in rows if "Error" not in r], plots):
            console.print(f"plot: {p}")


__all__ = ["default_entries", "leaderboard", "load_datasets", "plot_leaderboard", "real"]
