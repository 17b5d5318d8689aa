"""``lookalike bench real``: a leaderboard on real data, lookalike's box trackers against the peers
(:mod:`lookalike.bench.leaderboard`)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import typer
from rich.markup import escape
from rich.table import Table

from lookalike.bench.datasets import DATASETS, PARTS, cut_sequence, load_datasets, resolve_data_root
from lookalike.bench.leaderboard import COLUMNS, leaderboard, leaderboard_results, plot_leaderboard, run_with_progress
from lookalike.bench.peers import PEERS, peer_status
from lookalike.bench.runner import default_entries, params_entry
from lookalike.cli.app import check_choice, check_outputs_or_fail, command_line, console, fail, failing, split_list
from lookalike.cli.bench import bench_app, write_csv, write_results
from lookalike.cli.progress import progress_bars
from lookalike.parallel import BACKENDS
from lookalike.tune.params_file import load_params, read_params

BOX_TRACKERS = ("sort", "boxtrack")  # lookalike trackers that need nothing but boxes and scores
_DATASETS_HELP = f"Datasets (comma-separated or repeated): {', '.join(DATASETS)}."


def _cell(value: Any) -> str:
    if isinstance(value, float):
        return "–" if not np.isfinite(value) else f"{value:.2f}" if abs(value) < 1e4 else f"{value:,.0f}"
    return str(value)


def print_leaderboard(rows: list[dict[str, Any]], combined: list[dict[str, Any]], counts: dict[str, int],
                      part: str) -> None:
    """One table per dataset, the combined ranking, and the entries that failed."""
    what = "" if part == "full" else f" ({part} halves)"
    for dataset in dict.fromkeys(r["Dataset"] for r in rows):
        table = Table(title=f"{dataset}: {counts[dataset]} sequence(s){what}, identical detections")
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
            failed = escape(f"{r['Dataset']} / {r['Tracker']} failed: {r['Error']}")
            console.print(f"[red]{failed}[/red]")


@bench_app.command("real")
def real(
    data: Path | None = typer.Option(None, "--data", help="Folder with mot15/, pigs/, hexbug/, mot17/ "
                                     "(default: $LOOKALIKE_DATA, else ../shared/data from the current directory)."),
    datasets: list[str] = typer.Option(list(DATASETS[:3]), "--datasets", help=_DATASETS_HELP),
    trackers: list[str] = typer.Option(list(BOX_TRACKERS), "--trackers", help="lookalike box trackers."),
    peers: list[str] = typer.Option(list(PEERS), "--peers",
                                    help="Peers to try ('none' for none); absent ones are skipped."),
    sequence: list[str] | None = typer.Option(None, "--sequence", help="Only this sequence or clip (repeatable or "
                                              "comma-separated)."),
    max_clips: int | None = typer.Option(None, "--max-clips", min=1, help="At most this many HexBug clips."),
    part: str = typer.Option("full", "--part", help="Score whole sequences ('full'), their first halves "
                             "(where boxtrack's bench presets were chosen: 'first') or second halves ('second')."),
    workers: int = typer.Option(1, "--workers", min=1, help="Local processes (or Ray CPUs for a local Ray)."),
    backend: str = typer.Option("local", "--backend", help=f"One of {', '.join(BACKENDS)}."),
    address: str | None = typer.Option(None, "--address", help="Ray cluster address (default: a local ray.init())."),
    json_path: Path | None = typer.Option(None, "--json", help="Write the tables as JSON (results schema)."),
    csv_path: Path | None = typer.Option(None, "--csv", help="Write the dataset rows as CSV."),
    plots: Path | None = typer.Option(None, "--plots", help="Folder for one bar chart per dataset."),
    params_file: Path | None = typer.Option(None, "--params", help="Parameter file of `lookalike tune`: adds a row "
                                            "labelled with its name ('tuned on this data' when chosen on a scored "
                                            "sequence)."),
) -> None:
    """Leaderboard on real data: HOTA, IDF1, MOTA, IDSW, frames/s and rank per dataset, and combined."""
    check_outputs_or_fail({"--json": json_path, "--csv": csv_path, "--plots": plots}, [params_file],
                          folders={"--plots"}, input_folders=[data])
    tracker_list, peer_list = split_list(trackers), [p for p in split_list(peers) if p != "none"]
    check_choice("--part", part, PARTS)
    check_choice("--backend", backend, BACKENDS)
    if address is not None and backend != "ray":
        fail(f"--address {address}: a Ray cluster address is for --backend ray (got --backend {backend})")
    for t in tracker_list:
        if t not in BOX_TRACKERS:
            fail(f"--trackers: {t!r} is not a box tracker; choose from {', '.join(BOX_TRACKERS)}")
    with failing(ValueError):
        status = peer_status(peer_list)
    if not tracker_list and params_file is None and all(why is not None for why in status.values()):
        fail("nothing to run: --trackers names no tracker and no peer of --peers is installed (the peers: "
             "`make bench-env`, then .venv-bench/bin/lookalike bench real)")
    with failing(ValueError, FileNotFoundError):
        seqs = load_datasets(resolve_data_root(data), split_list(datasets), sequences=split_list(sequence) or None,
                             max_clips=max_clips, workers=workers, backend=backend, address=address)
    seqs = [cut_sequence(s, part) for s in seqs]
    for name, why in status.items():
        if why is not None:
            console.print(f"[yellow]skipped peer {escape(name)}: {escape(str(why))}[/yellow]")
    entries = default_entries(tracker_list, [p for p, why in status.items() if why is None])
    if params_file is not None:
        with failing(ValueError):
            content = read_params(params_file)
            if content.tracker not in BOX_TRACKERS:
                raise ValueError(f"{params_file}: parameters for {content.tracker!r}; bench real runs "
                                 f"{', '.join(BOX_TRACKERS)}")
            entry = params_entry(str(params_file), content.tracker, load_params(params_file), content.chosen_on, seqs)
        console.print(f"{entry.label}: {content.tracker} with {params_file} (chosen on "
                      f"{', '.join(content.chosen_on) or 'unknown data'})")
        entries.append(entry)
    with progress_bars() as progress:
        results = run_with_progress(entries, seqs, workers=workers, backend=backend, address=address,
                                    progress=progress)
    rows, combined, per_seq = leaderboard(entries, seqs, results)
    counts = {d: sum(1 for s in seqs if s.dataset == d) for d in dict.fromkeys(s.dataset for s in seqs)}
    print_leaderboard(rows, combined, counts, part)
    if json_path is not None:
        write_results(leaderboard_results(part, rows, combined, per_seq, status, seqs, command_line(),
                                          {"datasets": split_list(datasets), "workers": workers}), json_path)
    write_csv(rows, csv_path, [*COLUMNS, "Error"])
    if plots is not None:
        try:
            written = plot_leaderboard([r for r in rows if "Error" not in r], plots)
        except OSError as exc:
            fail(f"--plots: cannot write into {plots}: {exc.strerror or exc}")
        for p in written:
            console.print(f"plot: {p}", markup=False)


__all__ = ["BOX_TRACKERS", "print_leaderboard", "real"]
