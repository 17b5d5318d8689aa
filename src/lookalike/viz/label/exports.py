"""Labels in and out: export to the simulator's truth format and to MOTChallenge, and load starting labels.

MOTChallenge rows: ``frame (1-based), agent id + 1, 0, 0, 0, 0, score, x, y, -1`` with the observer-frame position in
metres and a zero-size box; false positives and unlabelled detections are left out."""

from __future__ import annotations

import dataclasses
import json
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from lookalike.io import read_mot, write_mot
from lookalike.io.robot_sequences import read_robot_sequence, write_robot_sequence
from lookalike.sim import RobotSequence
from lookalike.viz.label.store import FORMAT, UNSET

MATCH_TOLERANCE_M = 1e-3


def _label_array(sequence: RobotSequence, labels: Sequence[Sequence[int]]) -> np.ndarray:
    a = sequence.arrays
    if len(labels) != len(a):
        raise ValueError(f"labels: {len(labels)} frames for a sequence of {len(a)} frames")
    out = np.full(a.det_label.shape, -1, dtype=int)
    for k, row in enumerate(labels):
        n = int(a.det_valid[k].sum())
        if len(row) != n:
            raise ValueError(f"labels: frame {k} has {len(row)} labels for {n} detections")
        out[k, :n] = row
    return out


def export_truth(sequence: RobotSequence, labels: Sequence[Sequence[int]], path: str | Path) -> tuple[Path, int]:
    """Write ``sequence`` with ``labels`` as its detection labels (unset ones as -1); returns the path and the
    number of unset labels."""
    lab = _label_array(sequence, labels)
    n_unset = int((lab == UNSET).sum())
    lab[lab == UNSET] = -1
    arrays = dataclasses.replace(sequence.arrays, det_label=lab)
    return write_robot_sequence(path, RobotSequence(sequence.config, sequence.seed, arrays)), n_unset


def export_mot(sequence: RobotSequence, labels: Sequence[Sequence[int]], path: str | Path) -> tuple[Path, int]:
    """Write the agent-labelled detections as MOTChallenge rows (see the module docstring).
    Returns the path and the number of rows."""
    lab = _label_array(sequence, labels)
    a = sequence.arrays
    k, j = np.nonzero(a.det_valid & (lab >= 0))
    rows = np.zeros((len(k), 10))
    rows[:, 0] = k + 1
    rows[:, 1] = lab[k, j] + 1
    rows[:, 6] = a.det_score[k, j]
    rows[:, 7:9] = a.det_position[k, j]
    rows[:, 9] = -1.0
    return write_mot(path, rows), len(rows)


def load_labels(path: str | Path, sequence: RobotSequence) -> list[list[int]]:
    """Starting labels for ``sequence`` from a label file (``.json``), a robot sequence with the same detections
    (``.jsonl``) or a MOTChallenge file of :func:`export_mot` (``.txt``, matched by frame and position)."""
    path = Path(path)
    if not path.is_file():
        raise ValueError(f"{path}: no such file")
    counts = sequence.arrays.det_valid.sum(axis=1)
    if path.suffix == ".json":
        try:
            data = json.loads(path.read_text())
        except json.JSONDecodeError as exc:
            raise ValueError(f"{path}: not JSON ({exc})") from None
        if not isinstance(data, dict) or data.get("format") != FORMAT:
            raise ValueError(f"{path}: not a {FORMAT} file")
        labels = data.get("labels")
        if not isinstance(labels, list) or [len(r) for r in labels] != counts.tolist():
            raise ValueError(f"{path}: its labels do not match the sequence's detections per frame")
        return [[int(v) for v in r] for r in labels]
    if path.suffix == ".jsonl":
        other = read_robot_sequence(path)
        b, a = other.arrays, sequence.arrays
        if b.det_valid.shape != a.det_valid.shape or not np.array_equal(b.det_valid, a.det_valid) \
                or not np.allclose(b.det_position, a.det_position, atol=MATCH_TOLERANCE_M):
            raise ValueError(f"{path}: its detections are not this sequence's detections")
        return [b.det_label[k, : int(n)].tolist() for k, n in enumerate(counts)]
    if path.suffix == ".txt":
        return _labels_from_mot(path, sequence)
    raise ValueError(f"{path}: expected a .json label file, a .jsonl sequence or a .txt MOTChallenge file")


def _labels_from_mot(path: Path, sequence: RobotSequence) -> list[list[int]]:
    table = read_mot(path)
    a = sequence.arrays
    if table.extra.shape[1] < 2:
        raise ValueError(f"{path}: no world x, y columns to match detections by position")
    labels = [[-1] * int(n) for n in a.det_valid.sum(axis=1)]
    for r in range(len(table)):
        k = int(table.frame[r]) - 1
        if k >= len(a):
            raise ValueError(f"{path}: frame {k + 1} is beyond the sequence's {len(a)} frames")
        n = len(labels[k])
        d = np.hypot(*(a.det_position[k, :n] - table.extra[r, :2]).T) if n else np.zeros(0)
        if not n or d.min() > MATCH_TOLERANCE_M:
            raise ValueError(f"{path}: row {r + 1} (frame {k + 1}) matches no detection of that frame")
        agent = int(table.track_id[r]) - 1
        if not 0 <= agent < sequence.config.n_agents:
            raise ValueError(f"{path}: row {r + 1} has id {agent + 1}, outside 1 .. {sequence.config.n_agents}")
        labels[k][int(np.argmin(d))] = agent
    return labels
