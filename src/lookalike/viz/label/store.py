"""A person's labels of a robot sequence's detections (agent id ``0 .. N-1``, ``-1`` false positive, :data:`UNSET`
-2), saved atomically to ``<sequence stem>.labels.json`` after every change."""

from __future__ import annotations

import json
import math
import threading
import time
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from lookalike.eval import identification_success_rate
from lookalike.io.outputs import write_atomic

FORMAT = "lookalike-labels"
VERSION = 1
UNSET = -2


def label_path_for(sequence_path: str | Path) -> Path:
    """The label file beside ``sequence_path``: ``<folder>/<stem>.labels.json``."""
    p = Path(sequence_path)
    return p.with_name(f"{p.stem}.labels.json")


def _check_labels(labels: Sequence[Sequence[int]], counts: Sequence[int], n_agents: int, what: str) -> list[list[int]]:
    if len(labels) != len(counts):
        raise ValueError(f"{what}: {len(labels)} frames of labels for a sequence of {len(counts)} frames")
    out = []
    for k, (row, n) in enumerate(zip(labels, counts)):
        row = [int(v) for v in row]
        if len(row) != n:
            raise ValueError(f"{what}: frame {k} has {len(row)} labels for {n} detections")
        if any(v < UNSET or v >= n_agents for v in row):
            raise ValueError(f"{what}: frame {k} has a label outside -2 .. {n_agents - 1}: {row}")
        out.append(row)
    return out


class LabelStore:
    """Per-detection labels of one sequence (``counts (T,)`` detections per frame, ``n_agents`` robots), thread-safe,
    saved to ``path`` after every change; ``initial`` labels (default unset) and their ``source`` when it is new."""

    def __init__(self, path: str | Path, sequence_name: str, counts: Sequence[int], n_agents: int,
                 initial: Sequence[Sequence[int]] | None = None, source: str = "empty") -> None:
        if n_agents < 1:
            raise ValueError(f"n_agents must be >= 1, got {n_agents}")
        self.path = Path(path)
        self.sequence_name = sequence_name
        self.counts = [int(c) for c in counts]
        self.n_agents = int(n_agents)
        self._lock = threading.Lock()
        self.benchmark: dict[str, Any] | None = None
        self.loaded_from_file = self.path.exists()
        if self.loaded_from_file:
            self._load()
        else:
            if initial is None:
                initial = [[UNSET] * n for n in self.counts]
            self.labels = _check_labels(initial, self.counts, self.n_agents, "initial labels")
            self.source = source
            self._save()

    def _load(self) -> None:
        try:
            data = json.loads(self.path.read_text())
        except (OSError, json.JSONDecodeError) as exc:
            raise ValueError(f"{self.path}: not a readable label file ({exc})") from None
        if not isinstance(data, dict) or data.get("format") != FORMAT or data.get("version") != VERSION:
            raise ValueError(f"{self.path}: not a {FORMAT} v{VERSION} file")
        if data.get("sequence") != self.sequence_name:
            raise ValueError(f"{self.path}: labels of {data.get('sequence')!r}, not of {self.sequence_name!r}")
        if data.get("n_agents") != self.n_agents:
            raise ValueError(f"{self.path}: made for {data.get('n_agents')} agents, the sequence has {self.n_agents}")
        self.labels = _check_labels(data.get("labels", []), self.counts, self.n_agents, str(self.path))
        self.source = str(data.get("source", "file"))
        self.benchmark = data.get("benchmark")

    def _save(self) -> None:
        doc = {"format": FORMAT, "version": VERSION, "sequence": self.sequence_name, "n_frames": len(self.counts),
               "n_agents": self.n_agents, "counts": self.counts, "labels": self.labels, "source": self.source,
               "benchmark": self.benchmark, "saved_at": time.time()}
        write_atomic(self.path, json.dumps(doc, separators=(",", ":")))

    def set_label(self, frame: int, detection: int, label: int) -> None:
        """Set one detection's label (agent id, -1 false positive, -2 unset) and save."""
        for name, v in (("frame", frame), ("detection", detection), ("label", label)):
            if isinstance(v, bool) or not isinstance(v, int):
                raise ValueError(f"{name} must be an integer, got {v!r}")  # noqa: TRY004 (bad input: ValueError)
        if not 0 <= frame < len(self.counts):
            raise ValueError(f"frame {frame} out of range 0 .. {len(self.counts) - 1}")
        if not 0 <= detection < self.counts[frame]:
            raise ValueError(f"detection {detection} out of range for frame {frame} ({self.counts[frame]} detections)")
        if not UNSET <= label < self.n_agents:
            raise ValueError(f"label {label} outside -2 .. {self.n_agents - 1}")
        with self._lock:
            if self.benchmark and self.benchmark.get("finished_at") is not None:
                raise ValueError("the benchmark session has finished; labels are locked")
            self.labels[frame][detection] = label
            self._save()

    def snapshot(self) -> list[list[int]]:
        """A copy of all labels, one list per frame."""
        with self._lock:
            return [list(r) for r in self.labels]

    def start_benchmark(self, now: float | None = None) -> dict[str, Any]:
        """Start timing a human-benchmark session (idempotent: a started session keeps its start)."""
        with self._lock:
            if self.benchmark is None:
                self.benchmark = {"started_at": time.time() if now is None else now, "finished_at": None}
                self._save()
            return dict(self.benchmark)

    def finish_benchmark(self, truth: Sequence[np.ndarray], now: float | None = None) -> dict[str, Any]:
        """Stop the session, score it against ``truth`` and save the result (idempotent)."""
        with self._lock:
            if self.benchmark is None:
                raise ValueError("the benchmark session has not started")
            if self.benchmark.get("finished_at") is None:
                end = time.time() if now is None else now
                result = score_labels(self.labels, truth, self.n_agents)
                self.benchmark = {**self.benchmark, "finished_at": end,
                                  "duration_s": end - self.benchmark["started_at"], **result}
                self._save()
            return dict(self.benchmark)


def score_labels(labels: Sequence[Sequence[int]], truth: Sequence[np.ndarray], n_agents: int) -> dict[str, Any]:
    """Success rate of ``labels`` against ``truth`` up to the last labelled frame (unset is wrong) and over the whole
    sequence (None without detections), with the counts scored, correct and unset."""
    if len(labels) != len(truth):
        raise ValueError(f"labels has {len(labels)} frames, truth {len(truth)}")
    touched = [k for k, row in enumerate(labels) if any(v != UNSET for v in row)]
    last = touched[-1] if touched else -1
    # Unset becomes agent id N, which no truth label equals: always wrong.
    pred = [np.where(np.asarray(r, dtype=int) == UNSET, n_agents, np.asarray(r, dtype=int)) for r in labels]
    true = [np.asarray(t, dtype=int).ravel() for t in truth]
    n_scored = int(sum(len(t) for t in true[: last + 1]))
    correct = int(sum(int(np.sum(p == t)) for p, t in zip(pred[: last + 1], true[: last + 1])))
    unset = int(sum(int(np.sum(np.asarray(r) == UNSET)) for r in labels[: last + 1]))
    return {
        "frames_scored": last + 1,
        "detections_scored": n_scored,
        "correct": correct,
        "unset": unset,
        "success_rate": _finite(identification_success_rate(pred[: last + 1], true[: last + 1])),
        "success_rate_all": _finite(identification_success_rate(pred, true)),
    }


def _finite(x: float) -> float | None:
    """``x``, or None for NaN (JSON has no NaN)."""
    return None if math.isnan(x) else x
