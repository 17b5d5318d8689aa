"""Seed A's Table III protocol on recordings: success rate by sequence length.

For each length (frames), ``draws`` windows of that length are drawn at random (seeded) from the
recordings, each identifier runs on every window from a fresh state, and the success rate is
correct labels / detections over the windows of that length; the ``Total`` column runs each
identifier over every recording whole. Recordings are robot sequences (simulated, or rendered-pixel
runs written in the robot-sequence format) with the truth in each detection's label.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from lookalike.bench.ident import build_identifier, sequence_seeds
from lookalike.bench.progress import ProgressFactory, no_progress
from lookalike.eval import identification_success_rate, localisation_error
from lookalike.io.robot_sequences import read_robot_sequence
from lookalike.loop import run
from lookalike.sim import RobotSequence, preset, preset_label, simulate_robots
from lookalike.trackers.identity import agent_positions, labels_from_tracks
from lookalike.types import Frame

DEFAULT_LENGTHS = (200, 400, 800)
DEFAULT_DRAWS = 4


def draw_windows(lengths: Sequence[int], recording_lengths: Sequence[int], draws: int,
                 seed: int) -> list[tuple[int, int, int]]:
    """``(length, recording, first frame)`` of ``draws`` random windows per length; recordings shorter
    than a length are never drawn for it; a length no recording holds raises ``ValueError``."""
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
    frames: list[Frame] = [seq.frame(k) for k in range(first, first + length)]
    predicted: list[np.ndarray] = []
    positions = np.full((length, seq.config.n_agents, 2), np.nan)

    def sink(frame: Frame, tracks: Any) -> None:
        positions[len(predicted)] = agent_positions(tracks, seq.config.n_agents)
        predicted.append(labels_from_tracks(len(frame.detections), tracks))

    run(build_identifier(name, seq), frames, sink)
    truth = seq.true_labels()[first:first + length]
    return predicted, truth, positions, seq.true_positions_visible()[first:first + length]


def table3_rows(recordings: Sequence[RobotSequence], trackers: Sequence[str], lengths: Sequence[int] = DEFAULT_LENGTHS,
                draws: int = DEFAULT_DRAWS, seed: int = 0,
                progress: ProgressFactory = no_progress) -> list[dict[str, Any]]:
    """One row per identifier: success rate (%) per length, the total over whole recordings, and the
    localisation error (m) over whole recordings. All recordings must share N and M."""
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


def table3_table(setups: Sequence[str], trackers: Sequence[str], sequences: int, frames: int, seed: int,
                 noise: str, lengths: Sequence[int], draws: int, recordings: Path | None = None,
                 progress: ProgressFactory = no_progress) -> list[dict[str, Any]]:
    """Rows of :func:`table3_rows` with a ``Setup`` column: on the robot-sequence ``.jsonl`` files of
    folder ``recordings`` when given, else per set-up on the simulated test sequences of ``bench ident``
    (``sequences`` × ``frames``, noise model ``noise``, seeds from ``seed``)."""
    if any(n < 1 for n in lengths):
        raise ValueError(f"--lengths: frame counts must be positive, got {list(lengths)}")
    groups: list[tuple[str, list[RobotSequence]]] = []
    if recordings is not None:
        files = sorted(recordings.glob("*.jsonl")) if recordings.is_dir() else []
        if not files:
            raise ValueError(f"--recordings: no .jsonl robot sequences in {recordings}")
        groups.append((recordings.name, [read_robot_sequence(f) for f in files]))
    else:
        for setup in setups:
            cfg = preset(setup, noise)
            groups.append((preset_label(setup),
                           [simulate_robots(cfg, frames, s) for s in sequence_seeds([setup], sequences, seed)]))
    rows = []
    for label, seqs in groups:
        rows += [{"Setup": label, **r} for r in table3_rows(seqs, trackers, lengths, draws, seed, progress)]
    return rows


__all__ = ["DEFAULT_DRAWS", "DEFAULT_LENGTHS", "draw_windows", "table3_rows", "table3_table"]
