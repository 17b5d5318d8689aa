"""Open a labelling session: read the sequence, load or create its label file."""

from __future__ import annotations

import os
from collections.abc import Sequence
from pathlib import Path

from lookalike.io.robot_sequences import read_robot_sequence
from lookalike.viz.label.human import check_labeller
from lookalike.viz.label.server import LabelApp
from lookalike.viz.label.store import LabelStore, label_path_for


def open_label_app(sequence_path: str | Path, initial: Sequence[Sequence[int]] | None = None,
                   source: str = "empty", benchmark: bool = False, fresh: bool = False,
                   labeller: str = "anonymous", results_dir: str | Path | None = None) -> LabelApp:
    """A :class:`LabelApp` for the robot sequence at ``sequence_path``: saved labels win over ``initial`` (``fresh``
    moves them to ``.bak`` first); a benchmark starts from none. ``ValueError`` for bad files or labeller ids."""
    sequence_path = Path(sequence_path)
    check_labeller(labeller)
    if not sequence_path.is_file():
        raise ValueError(f"{sequence_path}: no such sequence file")
    if benchmark and initial is not None:
        raise ValueError("benchmark mode starts from no labels; do not pass starting labels")
    sequence = read_robot_sequence(sequence_path)
    label_path = label_path_for(sequence_path)
    if fresh and label_path.exists():
        os.replace(label_path, label_path.with_name(label_path.name + ".bak"))
    counts = sequence.arrays.det_valid.sum(axis=1).tolist()
    store = LabelStore(label_path, sequence_path.name, counts, sequence.config.n_agents, initial, source)
    bench = store.benchmark
    if not benchmark and bench is not None and bench.get("finished_at") is None:
        raise ValueError(f"{label_path}: a benchmark session is under way; continue it with --benchmark")
    if benchmark and store.source != "empty":
        raise ValueError(f"{label_path}: labels started from {store.source}; a benchmark needs --fresh")
    return LabelApp(sequence_path, sequence, store, benchmark, labeller, results_dir)
