"""``lookalike bench``: benchmarks that print tables. ``bench ident`` is seed A's Table I.

``lookalike bench ident`` simulates the same test sequences for every identifier (by default 10
sequences × 1,000 frames per set-up, seeds ``seed + 1000·setup + sequence`` with the default
``seed`` 900000, disjoint from the seeds below 100000 used for tuning and training) and reports,
per set-up and identifier, the identification success rate (correct labels / all detections, a
false positive labelled as such counting as correct), the localisation error (mean distance in
metres between each agent's identified position and its true position while it is in view) and
the identifier's frames per second (tracking only, simulation excluded).
"""

from __future__ import annotations

import csv
import json
import time
from pathlib import Path
from collections.abc import Sequence
from typing import Any

import numpy as np
import typer
from rich.table import Table

from lookalike.cli.app import app, console, fail
from lookalike.eval import identification_success_rate, localisation_error
from lookalike.sim import (
    PRESET_NAMES,
    RobotSequence,
    preset,
    preset_label,
    simulate_robots,
)
from lookalike.trackers import make_tracker, tracker_names, tracker_parameters
from lookalike.trackers.identity import agent_positions, labels_from_tracks

bench_app = typer.Typer(help="Benchmarks that print tables (also written with --json/--csv).", no_args_is_help=True)
app.add_typer(bench_app, name="bench")

IDENT_TRACKERS = ("kalman_ha", "kalman_ha2", "jpda")
IDENT_COLUMNS = ("Setup", "Tracker", "Success rate (%)", "Localisation error (m)", "Frames/s", "Detections")
DEFAULT_SEED = 900_000


def _build(name: str, sequence: RobotSequence) -> Any:
    """Tracker ``name`` configured for the sequence's N (and M for trackers with slots)."""
    known = {p.name for p in tracker_parameters(name)}
    cfg = sequence.config
    params = {k: v for k, v in (("n_agents", cfg.n_agents), ("n_slots", cfg.max_detections)) if k in known}
    return make_tracker(name, **params)


def run_identifier(name: str, sequences: list[RobotSequence]) -> dict[str, float]:
    """Success rate, localisation error, frames/s and detection count of tracker ``name``."""
    predicted, truth, est, true_pos = [], [], [], []
    elapsed, n_frames = 0.0, 0
    for seq in sequences:
        tracker = _build(name, seq)
        frames = list(seq.frames())
        n = seq.config.n_agents
        positions = np.full((len(frames), n, 2), np.nan)
        outputs = []
        t0 = time.perf_counter()
        for frame in frames:
            outputs.append(tracker.update(frame))
        elapsed += time.perf_counter() - t0
        n_frames += len(frames)
        for k, (frame, tracks) in enumerate(zip(frames, outputs)):
            predicted.append(labels_from_tracks(len(frame.detections), tracks))
            positions[k] = agent_positions(tracks, n)
        truth.extend(seq.true_labels())
        est.append(positions)
        true_pos.append(seq.true_positions_visible())
    return {
        "success": identification_success_rate(predicted, truth),
        "loc_error": localisation_error(np.concatenate(est), np.concatenate(true_pos)),
        "fps": n_frames / elapsed if elapsed > 0 else float("inf"),
        "detections": float(sum(len(p) for p in predicted)),
    }


def ident_table(setups: list[str], trackers: list[str], sequences: int, frames: int,
                seed: int = DEFAULT_SEED) -> list[dict[str, Any]]:
    """Rows (keys :data:`IDENT_COLUMNS`) for every set-up and tracker, on identical sequences."""
    rows = []
    for setup in setups:
        cfg = preset(setup)
        seqs = [simulate_robots(cfg, frames, seed + 1000 * PRESET_NAMES.index(setup) + k) for k in range(sequences)]
        for name in trackers:
            r = run_identifier(name, seqs)
            rows.append({
                "Setup": preset_label(setup), "Tracker": name, "Success rate (%)": round(100 * r["success"], 2),
                "Localisation error (m)": round(r["loc_error"], 3), "Frames/s": round(r["fps"], 1),
                "Detections": int(r["detections"]),
            })
    return rows


def _split(values: list[str]) -> list[str]:
    return [v.strip() for item in values for v in item.split(",") if v.strip()]


def print_rows(title: str, rows: list[dict[str, Any]], columns: Sequence[str] | None = None) -> None:
    """Print table rows (dicts) with rich: text columns left, numbers right with thousands separators."""
    columns = list(columns if columns is not None else (rows[0] if rows else []))
    table = Table(title=title)
    for c in columns:
        table.add_column(c, justify="left" if c in ("Setup", "Tracker", "Identifier") else "right")
    for r in rows:
        table.add_row(*(f"{r[c]:,}" if isinstance(r[c], (int, float)) else str(r[c]) for c in columns))
    console.print(table)


def write_rows(rows: list[dict[str, Any]], json_path: Path | None, csv_path: Path | None) -> None:
    """Write table rows as JSON (a list of objects) and/or CSV."""
    if json_path is not None:
        json_path.parent.mkdir(parents=True, exist_ok=True)
        json_path.write_text(json.dumps(rows, indent=2) + "\n")
    if csv_path is not None and rows:
        csv_path.parent.mkdir(parents=True, exist_ok=True)
        with csv_path.open("w", newline="") as fh:
            writer = csv.DictWriter(fh, fieldnames=list(rows[0]))
            writer.writeheader()
            writer.writerows(rows)


@bench_app.command("ident")
def ident(
    setups: list[str] = typer.Option(list(PRESET_NAMES), "--setups", help="Presets (comma-separated or repeated)."),
    trackers: list[str] = typer.Option(list(IDENT_TRACKERS), "--trackers", help="Identifiers to compare."),
    sequences: int = typer.Option(10, "--sequences", min=1, help="Test sequences per set-up."),
    frames: int = typer.Option(1000, "--frames", min=1, help="Frames per sequence."),
    seed: int = typer.Option(DEFAULT_SEED, "--seed", help="Base seed of the test sequences."),
    json_path: Path | None = typer.Option(None, "--json", help="Also write the rows as JSON."),
    csv_path: Path | None = typer.Option(None, "--csv", help="Also write the rows as CSV."),
) -> None:
    """Seed A's Table I: identification success rate per set-up and identifier (+ error, speed)."""
    setup_list, tracker_list = _split(setups), _split(trackers)
    for s in setup_list:
        if s not in PRESET_NAMES:
            fail(f"--setups: unknown preset {s!r}; known: {', '.join(PRESET_NAMES)}")
    known = tracker_names()
    for t in tracker_list:
        if t not in known:
            fail(f"--trackers: unknown tracker {t!r}; known: {', '.join(known)}")
    try:
        rows = ident_table(setup_list, tracker_list, sequences, frames, seed)
    except (ValueError, FileNotFoundError) as exc:
        fail(str(exc))
    labels = [preset_label(s) for s in setup_list]
    table = Table(title=f"Robot identification success rate, {sequences} × {frames} frames per set-up")
    table.add_column("Tracker")
    for label in labels:
        table.add_column(label, justify="right")
    for name in tracker_list:
        cells = []
        for label in labels:
            row = next(r for r in rows if r["Setup"] == label and r["Tracker"] == name)
            cells.append(f"{row['Success rate (%)']:.1f}%")
        table.add_row(name, *cells)
    console.print(table)
    detail = Table(title="Per set-up details")
    for column in IDENT_COLUMNS:
        detail.add_column(column, justify="left" if column in ("Setup", "Tracker") else "right")
    for row in rows:
        detail.add_row(*(f"{row[c]:,}" if isinstance(row[c], (int, float)) else str(row[c]) for c in IDENT_COLUMNS))
    console.print(detail)
    write_rows(rows, json_path, csv_path)


__all__ = ["bench_app", "ident_table", "run_identifier", "write_rows"]
