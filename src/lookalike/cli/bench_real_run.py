"""Jobs of ``lookalike bench real`` and the backends that run them: serial, processes, Ray.

A job is one tracker entry on one sequence; it returns the sequence's scores (counts that combine)
and the tracking time. Every backend maps the same pure function over the same jobs and returns
the results in job order, so the tables do not depend on the backend (frames/s aside). The Ray
backend uses Ray's task API (``ray.remote`` / ``ray.get``), connecting to ``address`` or starting
a local instance (``ray.init()``); the sequences are put in Ray's object store once.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from lookalike.cli.bench_peers import run_peer
from lookalike.cli.bench_real_data import RealSequence
from lookalike.eval import evaluate_points, evaluate_sequence
from lookalike.io import MotTable, tracks_to_rows
from lookalike.trackers import make_tracker
from lookalike.types import Detections, Frame

BACKENDS = ("local", "ray")
# boxtrack's parameters per dataset where its detector differs from MOT15's, each chosen on the first
# half of that dataset alone (benchmarks/real_boxtrack_grid.py; best HOTA + IDF1 + MOTA):
# - pigs (frames 1..315): high/birth score ∈ {0.5, 0.7, 0.8, 0.9};
# - hexbug (frames 1..50 of each clip, blob detector): match_iou ∈ {0.01, 0.05, 0.1, 0.3},
#   n_init ∈ {2, 3}, report, tentative_iou ∈ {0.1, 0.3}, reid_distance ∈ {0.5, 1, 2},
#   max_age_s ∈ {1, 3} (blobs of 10 fps bugs barely overlap from frame to frame).
# MOT15 uses boxtrack's defaults, chosen on the first halves of its sequences.
DATASET_PARAMS: dict[str, dict[str, dict[str, Any]]] = {
    "pigs": {"boxtrack": {"high_score": 0.7, "birth_score": 0.7}},
    "hexbug": {"boxtrack": {"match_iou": 0.01, "n_init": 2, "report": "detection", "tentative_iou": 0.1,
                            "reid_distance": 2.0, "max_age_s": 1.0}},
}
HEXBUG_RADIUS_PX = 120.0  # a box centre lies about half a bug from its head (benchmarks/hexbug_blobs.py)


@dataclass(frozen=True)
class Entry:
    """One row of a table: a lookalike tracker with parameters, or a peer (``kind="peer"``)."""

    label: str
    name: str
    kind: str = "lookalike"
    params: dict[str, Any] = field(default_factory=dict)
    closed_set: bool = False  # pass the sequence's documented target count as ``max_targets``


def track_rows(entry: Entry, seq: RealSequence,
               dataset_params: dict[str, dict[str, dict[str, Any]]] | None = None) -> np.ndarray:
    """MOTChallenge rows ``(k, 10)`` of ``entry`` on ``seq``; ``dataset_params[dataset][tracker]``
    are parameters chosen per dataset (overridden by the entry's own)."""
    dataset_params = DATASET_PARAMS if dataset_params is None else dataset_params
    if entry.kind == "peer":
        return run_peer(entry.name, seq)
    params = {**dataset_params.get(seq.dataset, {}).get(entry.name, {}), **entry.params}
    if entry.closed_set and seq.n_targets is not None:
        params["max_targets"] = seq.n_targets
    tracker = make_tracker(entry.name, **params)
    out = []
    for k in range(seq.length):
        dets = Detections(xywh=seq.det_xywh[k], score=seq.det_score[k])
        out.append(tracks_to_rows(k, tracker.update(Frame(index=k, time=k / seq.frame_rate, detections=dets))))
    return np.vstack(out) if out else np.zeros((0, 10))


def score_rows(seq: RealSequence, rows: np.ndarray, radius: float = HEXBUG_RADIUS_PX) -> dict[str, float]:
    """Metrics of result rows against the sequence's ground truth (boxes, or points for HexBug)."""
    if seq.gt is not None:
        return evaluate_sequence(seq.gt, MotTable.from_rows(rows), num_frames=seq.length, benchmark="MOT15")
    if seq.gt_points is None:
        raise ValueError(f"sequence {seq.name}: no ground truth")
    frame, ids, xy = seq.gt_points
    centres = rows[:, 2:4] + rows[:, 4:6] / 2
    return evaluate_points(frame, ids, xy, rows[:, 0].astype(int), rows[:, 1].astype(int), centres,
                           radius=radius, num_frames=seq.length)


def run_job(job: tuple[Entry, RealSequence]) -> dict[str, Any]:
    """Track and score one (entry, sequence); a failing tracker gives ``error`` instead of scores."""
    entry, seq = job
    t0 = time.perf_counter()
    try:
        rows = track_rows(entry, seq)
    except Exception as exc:  # noqa: BLE001 - a peer's failure is reported in the table, never fatal
        return {"error": f"{type(exc).__name__}: {exc}"[:300], "frames": seq.length, "seconds": 0.0}
    seconds = time.perf_counter() - t0
    return {"scores": score_rows(seq, rows), "frames": seq.length, "seconds": seconds}


def _ray_job(entry: Entry, seq: RealSequence) -> dict[str, Any]:
    return run_job((entry, seq))


def map_jobs(fn: Callable[[Any], Any], items: Sequence[Any], *, workers: int = 1,
             backend: str = "local", address: str | None = None) -> list[Any]:
    """``[fn(x) for x in items]`` serially, in ``workers`` processes, or as Ray tasks (in order)."""
    if backend not in BACKENDS:
        raise ValueError(f"backend: expected one of {BACKENDS}, got {backend!r}")
    if workers < 1:
        raise ValueError(f"workers must be >= 1, got {workers}")
    if backend == "ray":
        ray = _ray(address, workers)
        remote = ray.remote(fn)
        return list(ray.get([remote.remote(x) for x in items]))
    if workers > 1 and len(items) > 1:
        with ProcessPoolExecutor(max_workers=min(workers, len(items))) as pool:
            return list(pool.map(fn, items))
    return [fn(x) for x in items]


def job_pairs(entries: Sequence[Entry], sequences: Sequence[RealSequence]) -> list[tuple[Entry, RealSequence]]:
    """``(entry, sequence)`` for every sequence and entry, closed-set entries only where the count is known."""
    return [(e, s) for s in sequences for e in entries if not (e.closed_set and s.n_targets is None)]


def run_jobs(entries: Sequence[Entry], sequences: Sequence[RealSequence], *, workers: int = 1,
             backend: str = "local", address: str | None = None) -> list[dict[str, Any]]:
    """Results of :func:`job_pairs`, in its order."""
    jobs = job_pairs(entries, sequences)
    if backend != "ray":
        return map_jobs(run_job, jobs, workers=workers, backend=backend)
    ray = _ray(address, workers)
    refs = {id(s): ray.put(s) for s in sequences}  # each sequence shipped once
    remote = ray.remote(_ray_job)
    return list(ray.get([remote.remote(e, refs[id(s)]) for e, s in jobs]))


def _ray(address: str | None, workers: int) -> Any:
    """The ``ray`` module, initialised (``address`` or a local instance; ``workers`` CPUs locally)."""
    try:
        import ray
    except ImportError:
        raise ValueError("backend 'ray' needs the ray package (pip install ray)") from None
    if not ray.is_initialized():
        if address:
            ray.init(address=address, ignore_reinit_error=True, log_to_driver=False)
        else:
            ray.init(num_cpus=workers if workers > 1 else None, ignore_reinit_error=True,
                     include_dashboard=False, log_to_driver=False)
    return ray
