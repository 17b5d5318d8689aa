"""The box-tracker peers of the speed benchmarks, each run the way its users call it.

Every runner takes sequences as lists of per-frame ``(xywh (n, 4), score (n,))`` arrays in pixels
and runs one fresh tracker per sequence; building each tracker's own input type (lookalike
``Frame``, ``supervision.Detections``) is part of the timed work, as it is for a user.

Peers (installed into .venv-bench by ``make bench``; a missing one is skipped with a message):

- reference SORT: Bewley's SORT as packaged on PyPI (``simple-online-realtime-tracking``, module
  ``sort.sort``; it wants a sixth input column, the detection index), with filterpy and lap as its
  requirements list them;
- ``trackers`` (Roboflow): ``SORTTracker`` and ``ByteTrackTracker``.

:func:`score_peers` runs the accuracy peers of ``lookalike bench real`` (:mod:`lookalike.bench.peers`:
norfair, supervision, ``trackers``, BoxMOT's motion-only trackers with their default presets) once on
the dev sequences, for the leave-out scripts to print beside their left-out figures.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

Sequence = list[tuple[np.ndarray, np.ndarray]]
Runner = Callable[[list[Sequence]], object]


def load_mot_sequences(root: str | Path) -> tuple[list[Sequence], list[float]]:
    """Per-frame ``(xywh, score)`` arrays of every MOTChallenge sequence under ``root`` and their frame rates."""
    from lookalike.io import find_sequences, read_mot

    seqs, rates = [], []
    for s in find_sequences(root):
        table = read_mot(s.det_path)
        order = np.argsort(table.frame, kind="stable")
        frame, xywh, conf = table.frame[order], table.xywh[order], table.conf[order]
        bounds = np.searchsorted(frame, np.arange(1, s.length + 2))
        seqs.append([(np.ascontiguousarray(xywh[lo:hi]), np.ascontiguousarray(conf[lo:hi]))
                     for lo, hi in zip(bounds[:-1], bounds[1:])])
        rates.append(float(s.frame_rate))
    return seqs, rates


def lookalike_runner(name: str, rates: list[float] | None = None) -> Runner:
    """Run lookalike's tracker ``name`` with its defaults, building one ``Frame`` per frame; returns
    the ``Tracks`` of every frame."""
    from lookalike import Detections, Frame, make_tracker

    def run(seqs: list[Sequence]) -> list[list[Any]]:
        out = []
        for k, frames in enumerate(seqs):
            rate = 30.0 if rates is None else rates[k]
            tracker = make_tracker(name)
            out.append([tracker.update(Frame(i, i / rate, Detections(xywh=xywh, score=score)))
                        for i, (xywh, score) in enumerate(frames)])
        return out

    return run


def reference_sort() -> Runner | None:
    """Bewley's reference SORT (None when not installed)."""
    try:
        from sort.sort import KalmanBoxTracker
        from sort.sort import Sort as ReferenceSort
    except ImportError:
        return None

    def run(seqs: list[Sequence]) -> list[list[np.ndarray]]:
        out = []
        for frames in seqs:
            KalmanBoxTracker.count = 0  # ids restart at 1 in every sequence
            tracker = ReferenceSort(max_age=1, min_hits=3, iou_threshold=0.3)
            rows = []
            for xywh, score in frames:
                dets = np.empty((len(xywh), 6))
                dets[:, :2] = xywh[:, :2]
                dets[:, 2:4] = xywh[:, :2] + xywh[:, 2:]
                dets[:, 4] = score
                dets[:, 5] = np.arange(len(xywh))
                rows.append(tracker.update(dets))
            out.append(rows)
        return out

    return run


def trackers_runner(kind: str, rates: list[float] | None = None) -> Runner | None:
    """Roboflow ``trackers``' ``SORTTracker`` (``kind="sort"``) or ``ByteTrackTracker`` (``"bytetrack"``)
    with their defaults (None when not installed)."""
    try:
        import supervision as sv
        from trackers import ByteTrackTracker, SORTTracker
    except ImportError:
        return None
    cls = SORTTracker if kind == "sort" else ByteTrackTracker

    def run(seqs: list[Sequence]) -> list[object]:
        out = []
        for k, frames in enumerate(seqs):
            tracker = cls(frame_rate=30.0 if rates is None else rates[k])
            last = None
            for xywh, score in frames:
                xyxy = np.empty_like(xywh)
                xyxy[:, :2] = xywh[:, :2]
                xyxy[:, 2:] = xywh[:, :2] + xywh[:, 2:]
                last = tracker.update(sv.Detections(xyxy=xyxy, confidence=score))
            out.append(last)
        return out

    return run


def reference_rows(result: list[np.ndarray]) -> list[tuple[int, np.ndarray]]:
    """The reference SORT's per-frame output as ``(id, xywh)`` pairs sorted by id."""
    frames = []
    for out in result:
        pairs = sorted((int(r[4]), np.array([r[0], r[1], r[2] - r[0], r[3] - r[1]])) for r in out)
        frames.append(pairs)
    return frames  # type: ignore[return-value]


def score_peers(seqs: list[Any], wanted: str, workers: int = 1) -> dict[str, dict[str, dict[str, float]]]:
    """Each installed peer named in ``wanted`` (comma-separated names of ``lookalike.bench.peers.PEERS``,
    ``all`` or ``none``) run once on ``seqs`` (``RealSequence``) with its own defaults: dataset -> peer ->
    scores combined over the dataset's sequences. A peer not installed is skipped with a printed line;
    one that fails on a dataset is left out of it with a printed line."""
    from lookalike.bench.peers import PEERS, peer_status
    from lookalike.bench.runner import Entry, run_jobs
    from lookalike.eval import combine

    names = list(PEERS) if wanted == "all" else [] if wanted == "none" else \
        [p.strip() for p in wanted.split(",") if p.strip()]
    status = peer_status(names) if names else {}
    for name, why in status.items():
        if why is not None:
            print(f"skipped peer {name}: {why}")
    entries = [Entry(p, p, kind="peer") for p, why in status.items() if why is None]
    results = run_jobs(entries, seqs, workers=workers) if entries else []
    out: dict[str, dict[str, dict[str, float]]] = {}
    for k, e in enumerate(entries):
        for d in dict.fromkeys(s.dataset for s in seqs):
            runs = [results[i * len(entries) + k] for i, s in enumerate(seqs) if s.dataset == d]
            if all("scores" in r for r in runs):
                out.setdefault(d, {})[e.label] = combine([r["scores"] for r in runs])
            else:
                print(f"peer {e.label} failed on {d}: {next(r['error'] for r in runs if 'error' in r)}")
    return out
