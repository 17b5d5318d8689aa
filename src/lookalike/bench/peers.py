"""Peer trackers for ``lookalike bench real``: optional imports, each run with its documented defaults.

A peer is a function ``(sequence) -> rows`` returning MOTChallenge rows ``(k, 10)`` (1-based frame,
id, left, top, width, height, ...) for the tracks it reports. Every peer receives the sequence's
detections (boxes and scores) and, where the library asks for it, the sequence's frame rate —
nothing else is changed from the library's defaults, except where a library has no default:

- norfair needs a distance and a threshold: ``distance_function="iou"`` (1 − IoU, the box
  distance of its documentation) with ``distance_threshold=0.7`` as in its box demos;
- BoxMOT's trackers are built by its own factory from its default preset (the tracker's
  ``configs/trackers/NAME.yaml``, as ``boxmot track --tracker NAME`` builds them) with only the
  appearance model and camera-motion compensation switched off (:data:`BOXMOT_CHANGES`); they get
  a black image of the sequence's size (the detections' extent where it is unknown; only the size
  is read), one call per frame.

A peer whose package is not installed is reported as skipped by :func:`peer_status`."""

from __future__ import annotations

import importlib.util
from collections.abc import Callable

import numpy as np

from lookalike.bench.datasets import RealSequence

PeerFn = Callable[[RealSequence], np.ndarray]


def _xyxy(xywh: np.ndarray) -> np.ndarray:
    out = np.array(xywh, dtype=float).reshape(-1, 4)
    out[:, 2:] += out[:, :2]
    return out


def _rows(frame0: int, ids: np.ndarray, xyxy: np.ndarray) -> np.ndarray:
    xyxy = np.asarray(xyxy, dtype=float).reshape(-1, 4)
    rows = np.full((len(xyxy), 10), -1.0)
    rows[:, 0] = frame0 + 1
    rows[:, 1] = ids
    rows[:, 2:4] = xyxy[:, :2]
    rows[:, 4:6] = xyxy[:, 2:] - xyxy[:, :2]
    rows[:, 6] = 1.0
    return rows


def _stack(chunks: list[np.ndarray]) -> np.ndarray:
    return np.vstack(chunks) if chunks else np.zeros((0, 10))


def _sv_detections(xywh: np.ndarray, score: np.ndarray):
    import supervision as sv  # type: ignore[import-not-found,import-untyped,unused-ignore]

    return sv.Detections(xyxy=_xyxy(xywh), confidence=np.asarray(score, dtype=float),
                         class_id=np.zeros(len(score), dtype=int))


def _run_sv_like(make: Callable[[], object], seq: RealSequence, method: str = "update") -> np.ndarray:
    """A tracker whose ``method(sv.Detections)`` returns ``sv.Detections`` carrying ``tracker_id``."""
    step = getattr(make(), method)
    out = []
    for k in range(seq.length):
        res = step(_sv_detections(seq.det_xywh[k], seq.det_score[k]))
        ids = np.asarray(res.tracker_id if res.tracker_id is not None else [], dtype=int)
        keep = ids >= 0
        if keep.any():
            out.append(_rows(k, ids[keep] + 1, np.asarray(res.xyxy)[keep]))
    return _stack(out)


def supervision_bytetrack(seq: RealSequence) -> np.ndarray:
    """supervision's ``sv.ByteTrack`` (defaults; ``frame_rate`` of the sequence)."""
    import supervision as sv  # type: ignore[import-not-found,import-untyped,unused-ignore]

    return _run_sv_like(lambda: sv.ByteTrack(frame_rate=max(round(seq.frame_rate), 1)), seq,
                        "update_with_detections")


def _roboflow(cls_name: str) -> PeerFn:
    def run(seq: RealSequence) -> np.ndarray:
        import trackers  # type: ignore[import-not-found,import-untyped,unused-ignore]

        cls = getattr(trackers, cls_name)
        return _run_sv_like(lambda: cls(frame_rate=float(seq.frame_rate)), seq)

    run.__doc__ = f"the ``trackers`` package's ``{cls_name}`` (defaults; ``frame_rate`` of the sequence)."
    return run


def norfair_iou(seq: RealSequence) -> np.ndarray:
    """norfair's ``Tracker`` on box corners with the IoU distance (threshold 0.7), other defaults."""
    import norfair  # type: ignore[import-not-found,import-untyped,unused-ignore]

    tracker = norfair.Tracker(distance_function="iou", distance_threshold=0.7)
    out = []
    for k in range(seq.length):
        xyxy = _xyxy(seq.det_xywh[k])
        dets = [norfair.Detection(points=b.reshape(2, 2), scores=np.full(2, s))
                for b, s in zip(xyxy, seq.det_score[k])]
        objs = tracker.update(detections=dets)
        if objs:
            out.append(_rows(k, np.array([o.id for o in objs]), np.array([o.estimate.reshape(4) for o in objs])))
    return _stack(out)


# BoxMOT tracker -> the options changed from its default preset: no appearance model (embeddings off),
# no camera-motion compensation (it needs real images). StrongSORT is absent: it cannot run without
# appearance embeddings.
BOXMOT_CHANGES: dict[str, dict[str, bool | None]] = {
    "botsort": {"use_embeddings": False, "use_cmc": False},
    "bytetrack": {},
    "ocsort": {},
    "deepocsort": {"use_embeddings": False, "cmc_off": True},
    "hybridsort": {"use_embeddings": False, "cmc_method": None},
    "boosttrack": {"use_embeddings": False, "use_cmc": False},
    "occluboost": {"use_embeddings": False, "use_cmc": False},
    "sfsort": {},
}


def _extent(seq: RealSequence) -> tuple[int, int]:
    """``(width, height)`` px reaching the right and bottom edges of every detection (a sequence of unknown size)."""
    xyxy = _xyxy(np.vstack([np.zeros((1, 4)), *seq.det_xywh]))
    return int(np.ceil(max(xyxy[:, 2].max(), 1.0))), int(np.ceil(max(xyxy[:, 3].max(), 1.0)))


def _boxmot(name: str) -> PeerFn:
    def run(seq: RealSequence) -> np.ndarray:
        import logging

        from boxmot import create_tracker  # type: ignore[import-not-found,import-untyped,unused-ignore]
        from boxmot.trackers import TrackerSpec  # type: ignore[import-not-found,import-untyped,unused-ignore]
        from boxmot.utils import logger as boxmot_logger  # type: ignore[import-not-found,import-untyped,unused-ignore]

        level = boxmot_logger.level
        boxmot_logger.setLevel(logging.WARNING)  # it logs every tracker's settings at INFO
        try:
            tracker = create_tracker(TrackerSpec(name=name, options=tuple(sorted(BOXMOT_CHANGES[name].items()))))
        finally:
            boxmot_logger.setLevel(level)
        needs = tracker.requirements
        if needs.embeddings or (needs.frame and not needs.frame_dimensions_only):
            raise RuntimeError(f"boxmot {name}: the preset still needs appearance or image content")
        width, height = seq.image_size or _extent(seq)
        image = np.zeros((height, width, 3), dtype=np.uint8)
        out = []
        for k in range(seq.length):
            xyxy = _xyxy(seq.det_xywh[k])
            dets = np.hstack([xyxy, np.asarray(seq.det_score[k], float).reshape(-1, 1), np.zeros((len(xyxy), 1))])
            res = np.asarray(tracker.update(dets, image), dtype=float).reshape(-1, 8)
            if len(res):
                out.append(_rows(k, res[:, 4].astype(int) + 1, res[:, :4]))  # BoxMOT counts ids from 0
        return _stack(out)

    changed = ", ".join(f"{k}={v}" for k, v in BOXMOT_CHANGES[name].items()) or "nothing"
    run.__doc__ = f"BoxMOT's ``{name}`` with its default preset; changed: {changed}."
    return run


# name -> (package to import, runner)
PEERS: dict[str, tuple[str, PeerFn]] = {
    "norfair": ("norfair", norfair_iou),
    "supervision-bytetrack": ("supervision", supervision_bytetrack),
    "trackers-sort": ("trackers", _roboflow("SORTTracker")),
    "trackers-bytetrack": ("trackers", _roboflow("ByteTrackTracker")),
    "trackers-ocsort": ("trackers", _roboflow("OCSORTTracker")),
    **{f"boxmot-{name}": ("boxmot.trackers.factory", _boxmot(name)) for name in BOXMOT_CHANGES},
}


def peer_status(names: list[str] | None = None) -> dict[str, str | None]:
    """Peer name -> None when importable, else the reason it is skipped."""
    out: dict[str, str | None] = {}
    for name in names if names is not None else list(PEERS):
        if name not in PEERS:
            raise ValueError(f"peers: unknown peer {name!r}; known: {', '.join(PEERS)}")
        package = PEERS[name][0]
        try:
            importlib.import_module(package)
        except ModuleNotFoundError:
            out[name] = f"{package.split('.')[0]} not installed"
        except Exception as exc:  # noqa: BLE001 - an installed package can fail to import (numpy ABI, ...)
            out[name] = f"{package} not importable ({type(exc).__name__}: {exc})"[:200]
        else:
            out[name] = None
    return out


def run_peer(name: str, seq: RealSequence) -> np.ndarray:
    """Rows ``(k, 10)`` of peer ``name`` on ``seq``."""
    if name not in PEERS:
        raise ValueError(f"peer: unknown peer {name!r}; known: {', '.join(PEERS)}")
    return PEERS[name][1](seq)


__all__ = ["BOXMOT_CHANGES", "PEERS", "PeerFn", "peer_status", "run_peer"]
