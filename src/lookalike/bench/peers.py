"""Peer trackers for ``lookalike bench real``: optional imports, each run with its documented defaults.

A peer is a function ``(sequence) -> rows`` returning MOTChallenge rows ``(k, 10)`` (1-based frame,
id, left, top, width, height, ...) for the tracks it reports. Every peer receives the sequence's
detections (boxes and scores) and, where the library asks for it, the sequence's frame rate —
nothing else is changed from the library's defaults, except where a library has no default:

- norfair needs a distance and a threshold: ``distance_function="iou"`` (1 − IoU, the box
  distance of its documentation) with ``distance_threshold=0.7`` as in its box demos;
- BoxMOT's trackers take an image; they get a black image of the sequence's size (they do not
  look at it), and frame indices follow the sequence.

A peer whose package is not installed is reported as skipped by :func:`peer_status`.
"""

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


def _boxmot(module: str, cls_name: str) -> PeerFn:
    def run(seq: RealSequence) -> np.ndarray:
        import logging

        mod = importlib.import_module(module)
        from boxmot.utils import logger as boxmot_logger  # type: ignore[import-not-found,import-untyped,unused-ignore]

        level = boxmot_logger.level
        boxmot_logger.setLevel(logging.WARNING)  # it logs every tracker's settings at INFO
        try:
            tracker = getattr(mod, cls_name)()
        finally:
            boxmot_logger.setLevel(level)
        width, height = seq.image_size or (1920, 1080)
        image = np.zeros((height, width, 3), dtype=np.uint8)
        out = []
        for k in range(seq.length):
            xyxy = _xyxy(seq.det_xywh[k])
            dets = np.hstack([xyxy, np.asarray(seq.det_score[k], float)[:, None], np.zeros((len(xyxy), 1))])
            res = np.asarray(tracker.update(dets, image), dtype=float).reshape(-1, 8)
            if len(res):
                out.append(_rows(k, res[:, 4].astype(int), res[:, :4]))
        return _stack(out)

    run.__doc__ = f"BoxMOT's ``{cls_name}`` (defaults)."
    return run


# name -> (package to import, runner)
PEERS: dict[str, tuple[str, PeerFn]] = {
    "norfair": ("norfair", norfair_iou),
    "supervision-bytetrack": ("supervision", supervision_bytetrack),
    "trackers-sort": ("trackers", _roboflow("SORTTracker")),
    "trackers-bytetrack": ("trackers", _roboflow("ByteTrackTracker")),
    "trackers-ocsort": ("trackers", _roboflow("OCSORTTracker")),
    "boxmot-bytetrack": ("boxmot", _boxmot("boxmot.trackers.bytetrack.bytetrack", "ByteTrack")),
    "boxmot-ocsort": ("boxmot", _boxmot("boxmot.trackers.ocsort.ocsort", "OcSort")),
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
            out[name] = f"{package} not installed"
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


__all__ = ["PEERS", "PeerFn", "peer_status", "run_peer"]
