"""Farazi and Behnke's Table III: success rate by sequence length, each identifier run from a fresh state on ``draws``
seeded random windows per length and over every whole recording (``Total``); human-benchmark sessions
(:mod:`lookalike.viz.label.human`) of the same set-up add a ``human`` row."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from lookalike.bench.ident import build_identifier, run_labels, sequence_seeds, setup_results
from lookalike.bench.progress import ProgressFactory, no_progress
from lookalike.eval import identification_success_rate, localisation_error
from lookalike.io.results import Results, percent_row_metrics
from lookalike.io.robot_sequences import read_robot_sequence
from lookalike.sim import RobotSequence, preset, preset_label, simulate_robots
from lookalike.viz.label.human import RESULT_GLOB, HumanResult, read_human_results

DEFAULT_LENGTHS = (200, 400, 800)
DEFAULT_DRAWS = 4
NO_VALUE = "—"  # a cell a row has no figure for (the human row's localisation)
HUMAN = "human"


def draw_windows(lengths: Sequence[int], recording_lengths: Sequence[int], draws: int,
                 seed: int) -> list[tuple[int, int, int]]:
    """``(length, recording, first frame)`` of ``draws`` random windows per length in recordings that hold it."""
    rng = np.random.default_rng(seed)
    out = []
    for length in lengths:
        fits = [i for i, n in enumerate(recording_lengths) if n >= length]
        if not fits:
            raise ValueError(f"--lengths: no recording has {length} frames (longest: {max(recording_lengths)})")
        for _ in range(draws):
            i = int(rng.choice(fits))
            out.append((int(length), i, int(rng.integers(0, recording_lengths[i] - length + 1))))
    return out


def _run_window(name: str, seq: RobotSequence, first: int, length: int) -> tuple[list, list, np.ndarray, np.ndarray]:
    frames = [seq.frame(k) for k in range(first, first + length)]
    predicted, positions = run_labels(build_identifier(name, seq), frames, seq.config.n_agents)
    truth = seq.true_labels()[first:first + length]
    return predicted, truth, positions, seq.true_positions_visible()[first:first + length]


def table3_rows(recordings: Sequence[RobotSequence], trackers: Sequence[str], lengths: Sequence[int] = DEFAULT_LENGTHS,
                draws: int = DEFAULT_DRAWS, seed: int = 0,
                progress: ProgressFactory = no_progress) -> list[dict[str, Any]]:
    """Per identifier: success rate (%) per length and in total, and localisation error (m)."""
    if not recordings:
        raise ValueError("no recordings")
    if draws < 1 or any(n < 1 for n in lengths):
        raise ValueError(f"draws and lengths must be positive, got draws={draws}, lengths={list(lengths)}")
    shapes = {(r.config.n_agents, r.config.max_detections) for r in recordings}
    if len(shapes) > 1:
        raise ValueError(f"recordings of different set-ups (N, M): {sorted(shapes)}")
    windows = draw_windows(lengths, [len(r) for r in recordings], draws, seed)
    step = progress("bench ident --lengths", len(trackers) * (len(windows) + len(recordings)))
    rows = []
    for name in trackers:
        row: dict[str, Any] = {"Tracker": name}
        for length in lengths:
            pred: list[np.ndarray] = []
            truth: list[np.ndarray] = []
            for n, i, first in windows:
                if n == length:
                    p, t, _, _ = _run_window(name, recordings[i], first, n)
                    pred += p
                    truth += t
                    step()
            row[f"{length} frames (%)"] = round(100 * identification_success_rate(pred, truth), 2)
        pred, truth, est, true_pos = [], [], [], []
        for rec in recordings:
            p, t, e, g = _run_window(name, rec, 0, len(rec))
            pred += p
            truth += t
            est.append(e)
            true_pos.append(g)
            step()
        row[f"Total, {sum(len(r) for r in recordings)} frames (%)"] = round(
            100 * identification_success_rate(pred, truth), 2)
        row["Localisation error (m)"] = round(localisation_error(np.concatenate(est), np.concatenate(true_pos)), 3)
        rows.append(row)
    return rows


def recording_files(folder: Path) -> list[Path]:
    """``folder``'s ``.jsonl`` robot sequences but a ``X.labelled.jsonl`` beside ``X.jsonl``."""
    files = sorted(folder.glob("*.jsonl")) if folder.is_dir() else []
    names = {f.name for f in files}
    return [f for f in files if not (f.name.endswith(".labelled.jsonl")
                                     and f.name.removesuffix(".labelled.jsonl") + ".jsonl" in names)]


def human_row(results: Sequence[HumanResult], lengths: Sequence[int], total_key: str) -> dict[str, Any]:
    """The ``human`` row: per length, the sessions that worked through at least that many frames; in total
    (``total_key``) all of them; :data:`NO_VALUE` where none counts."""
    def rate(chosen: Sequence[HumanResult]) -> float | str:
        detections = sum(r.detections_scored for r in chosen)
        return round(100 * sum(r.correct for r in chosen) / detections, 2) if detections else NO_VALUE

    ordered = sorted(lengths)
    longest = [max((n for n in ordered if n <= r.frames_scored), default=None) for r in results]
    row: dict[str, Any] = {"Tracker": HUMAN}
    for length in lengths:
        row[f"{length} frames (%)"] = rate([r for r, n in zip(results, longest) if n == length])
    row[total_key] = rate(results)
    row["Localisation error (m)"] = NO_VALUE
    return row


def human_sessions(results: Sequence[HumanResult], label: str) -> list[dict[str, Any]]:
    """One printed row per benchmark session."""
    return [{"Setup": label, "Labeller": r.labeller, "Sequence": r.sequence, "Frames": r.frames_scored,
             "Detections": r.detections_scored,
             "Success rate (%)": NO_VALUE if r.success_rate is None else round(100 * r.success_rate, 2),
             "Time (s)": round(r.duration_s, 1),
             "s/frame": NO_VALUE if r.seconds_per_frame is None else round(r.seconds_per_frame, 2)}
            for r in results]


def table3_table(setups: Sequence[str], trackers: Sequence[str], sequences: int, frames: int, seed: int,
                 noise: str, lengths: Sequence[int], draws: int, recordings: Path | None = None,
                 progress: ProgressFactory = no_progress, human: Path | None = None,
                 sessions: list[dict[str, Any]] | None = None) -> list[dict[str, Any]]:
    """Rows of :func:`table3_rows` with a ``Setup`` column, on the recordings in folder ``recordings`` or else on
    ``bench ident``'s sequences per set-up; human results in ``human`` (default ``recordings``) of a group's N and M
    add its :func:`human_row`, and their sessions go to ``sessions`` when given."""
    if any(n < 1 for n in lengths):
        raise ValueError(f"--lengths: frame counts must be positive, got {list(lengths)}")
    people = read_human_results(human) if human is not None else []
    if human is not None and not people:  # asked for by name: say why no 'human' row follows
        raise ValueError(f"--human: no result files ({RESULT_GLOB}, `lookalike label --benchmark`) in {human}")
    groups: list[tuple[str, list[RobotSequence]]] = []
    if recordings is not None:
        files = recording_files(recordings)
        if not files:
            raise ValueError(f"--recordings: no .jsonl robot sequences in {recordings}")
        groups.append((recordings.name, [read_robot_sequence(f) for f in files]))
        if human is None:
            people = read_human_results(recordings)
    else:
        for setup in setups:
            cfg = preset(setup, noise)
            groups.append((preset_label(setup),
                           [simulate_robots(cfg, frames, s) for s in sequence_seeds([setup], sequences, seed)]))
    rows = []
    for label, seqs in groups:
        group = table3_rows(seqs, trackers, lengths, draws, seed, progress)
        cfg = seqs[0].config
        mine = [r for r in people if (r.n_agents, r.max_detections) == (cfg.n_agents, cfg.max_detections)]
        if mine:
            group.append(human_row(mine, lengths, f"Total, {sum(len(r) for r in seqs)} frames (%)"))
            if sessions is not None:
                sessions += human_sessions(mine, label)
        rows += [{"Setup": label, **r} for r in group]
    if human is not None and not any(r["Tracker"] == HUMAN for r in rows):
        teams = sorted({f"M={r.max_detections}, N={r.n_agents}" for r in people})
        raise ValueError(f"--human: the result files in {human} are for {'; '.join(teams)}, not for the table's "
                         f"set-up(s) {', '.join(label for label, _ in groups)}")
    return rows


def _total_frames(row: dict[str, Any]) -> int:
    """The frame count of a :func:`table3_table` row's ``Total, N frames (%)`` column."""
    return next(int(k.split()[1]) for k in row if k.startswith("Total, "))


def table3_results(rows: list[dict[str, Any]], setups: Sequence[str], sequences: int, frames: int, seed: int,
                   noise: str, lengths: Sequence[int], draws: int, recordings: Path | None = None,
                   command: str = "") -> Results:
    """:func:`table3_table`'s rows as a results document (kind ``bench ident``): table ``ident_lengths`` with
    ``success_rate_<n>_frames`` per window length, ``success_rate`` over the whole recordings (fractions) and
    ``localisation_error_m``; the human row has no figure where it prints one of :data:`NO_VALUE`."""
    options = {"lengths": list(lengths), "draws": draws, "seed": seed}
    if recordings is None:
        doc, names = setup_results("bench ident", setups, sequences, frames, seed, command, {"noise": noise, **options})
    else:
        names = {}
        totals = {str(r["Setup"]): _total_frames(r) for r in rows}
        doc = Results("bench ident", command=command, sequences=len(recording_files(recordings)),
                      frames=sum(totals.values()), options={"recordings": str(recordings), **options})
    for r in rows:
        rename = {f"{n} frames (%)": f"success_rate_{n}_frames" for n in lengths}
        rename.update({k: "success_rate" for k in r if k.startswith("Total, ")})
        doc.add("ident_lengths", dataset=names.get(str(r["Setup"]), str(r["Setup"])), tracker=str(r["Tracker"]),
                metrics=percent_row_metrics(r, skip=("Setup", "Tracker"), rename=rename))
    return doc


__all__ = ["DEFAULT_DRAWS", "DEFAULT_LENGTHS", "HUMAN", "NO_VALUE", "draw_windows", "human_row", "human_sessions",
           "recording_files", "table3_results", "table3_rows", "table3_table"]
