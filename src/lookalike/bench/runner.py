"""Jobs of ``lookalike bench real``: one tracker entry on one sequence, giving combinable scores and tracking time,
run serially, in processes or on Ray, results in job order. Only a ``tuned`` entry gets the presets chosen on the
scored data; on blob detections ``boxtrack`` runs as ``lookalike track --detector blob`` does."""

from __future__ import annotations

import time
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from lookalike.bench.datasets import RealSequence
from lookalike.bench.peers import run_peer
from lookalike.bench.presets import SEQUENCE_PARAMS, TUNED_PARAMS
from lookalike.eval import evaluate_points, evaluate_sequence
from lookalike.io import MotTable
from lookalike.loop import RowCollector, run
from lookalike.parallel import JobPool
from lookalike.trackers import make_tracker
from lookalike.trackers.offline.closed_set import track_closed_set
from lookalike.trackers.offline.gap_fill import OfflineConfig, postprocess
from lookalike.types.mot_table import detection_rows as mot_detection_rows
from lookalike.vision.blob_auto import BOX_TRACKER_PARAMS
from lookalike.vision.blob_boxtrack import blob_boxtrack_config

HEXBUG_RADIUS_PX = 120.0  # a box centre lies about half a bug from its head (benchmarks/hexbug_blobs.py)
BLOB_DATASETS = frozenset({"hexbug"})  # detections from the blob detector (module doc)


@dataclass(frozen=True)
class Entry:
    """One row of a table: a lookalike tracker with parameters, or a peer (``kind="peer"``)."""

    label: str
    name: str
    kind: str = "lookalike"
    params: dict[str, Any] = field(default_factory=dict)
    closed_set: bool = False  # pass the sequence's documented target count as ``max_targets``
    offline: bool = False  # post-process the whole result (trackers.offline, OfflineConfig's defaults)
    tuned: bool = False  # add the parameters chosen on the scored data (TUNED_PARAMS, SEQUENCE_PARAMS)
    closed_offline: bool = False  # offline closed set of the documented count (track_closed_set)


TUNED_LABEL = "tuned on this data"


def default_entries(trackers: Sequence[str], peers: Sequence[str], closed_set: bool = True) -> list[Entry]:
    """lookalike trackers and peers with their defaults; with ``boxtrack`` also ``boxtrack-offline``, ``boxtrack
    (tuned on this data)`` and (``closed_set``) ``boxtrack-closed`` and ``boxtrack-closed-offline``."""
    entries = [Entry(t, t) for t in trackers]
    if "boxtrack" in trackers:
        entries += [Entry("boxtrack-offline", "boxtrack", offline=True),
                    Entry(f"boxtrack ({TUNED_LABEL})", "boxtrack", tuned=True)]
    if "boxtrack" in trackers and closed_set:
        entries += [Entry("boxtrack-closed", "boxtrack", closed_set=True),
                    Entry("boxtrack-closed-offline", "boxtrack", closed_set=True, closed_offline=True)]
    return entries + [Entry(p, p, kind="peer") for p in peers]


def params_entry(path: str, tracker: str, params: dict[str, Any], chosen_on: Sequence[str],
                 sequences: Sequence[RealSequence]) -> Entry:
    """The entry of a ``lookalike tune`` parameter file, labelled with its stem (and ``(tuned on this data)`` when
    ``chosen_on`` names a scored ``dataset/name`` or dataset)."""
    from pathlib import Path

    scored = {f"{s.dataset}/{base_name(s)}" for s in sequences} | {s.dataset for s in sequences}
    chosen = {str(c).split("[", 1)[0] for c in chosen_on}
    label = Path(path).stem + (f" ({TUNED_LABEL})" if chosen & scored else "")
    return Entry(label, tracker, params=dict(params))


def base_name(seq: RealSequence) -> str:
    """The sequence's name without the ``[first]``/``[second]`` of a cut (``cut_sequence``)."""
    return seq.name.split("[", 1)[0]


def sequence_params(entry: Entry, seq: RealSequence) -> dict[str, Any]:
    """The parameters chosen for a tuned ``entry``'s tracker on the first half of ``seq`` (empty if none)."""
    if entry.kind == "peer" or not entry.tuned:
        return {}
    return SEQUENCE_PARAMS.get(seq.dataset, {}).get(entry.name, {}).get(base_name(seq), {})


def entry_params(entry: Entry, seq: RealSequence) -> dict[str, Any]:
    """``entry``'s parameters on ``seq`` (tuned: dataset < sequence < its own; closed set: ``max_targets``)."""
    preset = TUNED_PARAMS.get(seq.dataset, {}) if entry.tuned else {}
    params = {**preset.get(entry.name, {}), **sequence_params(entry, seq), **entry.params}
    if entry.closed_set and seq.n_targets is not None:
        params["max_targets"] = seq.n_targets
    return params


def track_rows(entry: Entry, seq: RealSequence) -> np.ndarray:
    """MOTChallenge rows ``(k, 10)`` of ``entry`` on ``seq`` (``offline``: post-processed with the defaults)."""
    if entry.kind == "peer":
        return run_peer(entry.name, seq)
    params = entry_params(entry, seq)
    blob_boxtrack = entry.name == "boxtrack" and seq.dataset in BLOB_DATASETS
    if entry.closed_offline and seq.n_targets is not None:
        online = {k: v for k, v in params.items() if k != "max_targets"}
        if blob_boxtrack:  # as lookalike track --detector blob --offline
            online = {**BOX_TRACKER_PARAMS, **online}
        return track_closed_set(detection_rows(seq), seq.n_targets, seq.frame_rate, n_frames=seq.length,
                                online=online)
    tracker = make_tracker(entry.name, **params)
    if blob_boxtrack:
        tracker = type(tracker)(blob_tracker_config(tracker.config, seq, params))
    collect = RowCollector()
    run(tracker, seq.frames(), collect)
    rows = collect.rows()
    if entry.offline:
        rows = postprocess(rows, seq.frame_rate, OfflineConfig())
    return rows


def blob_tracker_config(config: Any, seq: RealSequence, params: dict[str, Any]) -> Any:
    """The ``boxtrack`` configuration ``lookalike track --detector blob`` runs on ``seq`` given ``params``."""
    counts = np.array([len(x) for x in seq.det_xywh], dtype=int)
    return blob_boxtrack_config(config, counts, params.keys(), seq.n_targets).config


def detection_rows(seq: RealSequence) -> np.ndarray:
    """The sequence's detections as MOTChallenge rows ``(k, 10)`` (1-based frames, id -1)."""
    blocks = []
    for k, (xywh, score) in enumerate(zip(seq.det_xywh, seq.det_score)):
        if len(xywh):
            blocks.append(mot_detection_rows(k + 1, xywh, score))
    return np.vstack(blocks) if blocks else np.zeros((0, 10))


def score_rows(seq: RealSequence, rows: np.ndarray, radius: float = HEXBUG_RADIUS_PX) -> dict[str, float]:
    """Metrics of result rows against the sequence's ground truth (boxes, or points for HexBug)."""
    if seq.gt is not None:
        return evaluate_sequence(seq.gt, MotTable.from_rows(rows), num_frames=seq.length, benchmark=seq.benchmark)
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


def _run_pair(entry: Entry, seq: RealSequence) -> dict[str, Any]:
    return run_job((entry, seq))


def job_pairs(entries: Sequence[Entry], sequences: Sequence[RealSequence]) -> list[tuple[Entry, RealSequence]]:
    """``(entry, sequence)`` per sequence and entry that can run there (a known count, chosen parameters)."""
    return [(e, s) for s in sequences for e in entries
            if not (e.closed_set and s.n_targets is None)
            and not (e.tuned and e.name not in TUNED_PARAMS.get(s.dataset, {})
                     and e.name not in SEQUENCE_PARAMS.get(s.dataset, {}))]


def run_jobs(entries: Sequence[Entry], sequences: Sequence[RealSequence], *, workers: int = 1,
             backend: str = "local", address: str | None = None) -> list[dict[str, Any]]:
    """Results of :func:`job_pairs`, in its order."""
    jobs = job_pairs(entries, sequences)
    with JobPool(min(workers, max(len(jobs), 1)), backend, address) as pool:
        shared = {id(s): pool.share(s) for s in sequences}  # each sequence shipped once
        return [p.result() for p in [pool.submit(_run_pair, e, shared[id(s)]) for e, s in jobs]]


__all__ = ["BLOB_DATASETS", "HEXBUG_RADIUS_PX", "SEQUENCE_PARAMS", "TUNED_LABEL", "TUNED_PARAMS",
           "Entry", "base_name", "blob_tracker_config",
           "default_entries", "detection_rows", "entry_params", "params_entry", "job_pairs",
           "run_job", "run_jobs", "score_rows",
           "sequence_params", "track_rows"]
