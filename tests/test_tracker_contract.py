"""One contract for every registered tracker (``tracker_names()``): what any caller may rely on.

Each tracker gets the input it needs: box trackers boxes and scores, appearance trackers also
unit feature vectors, world trackers ground positions (m), headings (rad) and beacon reports.
Cases: an empty frame, reset, a copy or pickle mid-sequence, permuted detection order, the ``detection_index``
round trip, time going backwards, 10,000 frames without memory growth, bad parameter values. A tracker registered
without a kind here fails :func:`test_every_tracker_has_a_kind`, so a new tracker joins the contract.

Known gaps are ``xfail(strict=True)`` entries in ``KNOWN_GAPS``: when a tracker is fixed, its
entry turns into a failure (XPASS) and must be removed.
"""

from __future__ import annotations

import collections
import copy
import dataclasses
import math
import pickle
import sys
import tracemalloc
import types
import typing
from collections.abc import Callable
from typing import Any

import numpy as np
import pytest

from lookalike.trackers import make_tracker, tracker_names
from lookalike.trackers.registry import tracker_class
from lookalike.types import Beacons, Detections, Frame

BOX, APPEARANCE, WORLD = "box", "appearance", "world"
KINDS = {
    "sort": BOX, "boxtrack": BOX,
    "deepsort": APPEARANCE, "diversort": APPEARANCE,
    "kalman_ha": WORLD, "kalman_ha2": WORLD, "jpda": WORLD, "lstm": WORLD, "set": WORLD,
}
# Identifiers report agents, not detections: the position is a confidence-weighted blend of the
# detections labelled as the agent, so the round trip checks the label and the heading instead.
IDENTIFIERS = {"lstm", "set"}
NAMES = tracker_names()
FPS = 25.0
N_TARGETS = 3
FEATURE_DIM = 8

# (tracker, case) -> why it fails today; empty when every tracker keeps the contract.
KNOWN_GAPS: dict[tuple[str, str], str] = {}


def _gap(name: str, case: str) -> list[Any]:
    reason = KNOWN_GAPS.get((name, case))
    return [pytest.mark.xfail(strict=True, reason=reason)] if reason else []


def _params(case: str) -> list[Any]:
    return [pytest.param(name, id=name, marks=_gap(name, case)) for name in NAMES]


# ---------------------------------------------------------------------------------------------
# Input for each kind of tracker


def _frame(k: int, n_targets: int = N_TARGETS, kind: str = BOX, order: np.ndarray | None = None,
           move: bool = True, time_s: float | None = None) -> Frame:
    """Frame ``k`` of a scene of ``n_targets`` well separated targets moving steadily (or standing
    still with ``move=False``); ``order`` permutes the detections."""
    i = np.arange(n_targets, dtype=float)
    step = k if move else 0
    score = 0.99 - 0.01 * i  # distinct scores: slot order (LSTM) does not depend on input order
    if kind == WORLD:
        position = np.column_stack([2.0 + 0.01 * step + 0.0 * i, -1.2 + 1.2 * i])  # metres ahead / left
        columns: dict[str, Any] = {"position": position, "heading": 0.3 * i - 0.3, "score": score}
    else:
        xywh = np.column_stack([60.0 + 200.0 * i + 1.0 * step, 100.0 + 0.5 * step + 0 * i,
                                np.full(n_targets, 40.0), np.full(n_targets, 80.0)])
        columns = {"xywh": xywh, "score": score}
        if kind == APPEARANCE:
            columns["feature"] = np.eye(FEATURE_DIM)[:n_targets]
    if order is not None:
        columns = {key: np.asarray(value)[order] for key, value in columns.items()}
    t = k / FPS if time_s is None else time_s
    beacons = Beacons.empty()
    if kind == WORLD and k % 3 == 0:  # each robot reports its heading every third frame
        heading = 0.3 * np.arange(N_TARGETS) - 0.3
        beacons = Beacons(agent_id=np.arange(N_TARGETS), t_sent=np.full(N_TARGETS, t - 0.02),
                          t_received=np.full(N_TARGETS, t), heading=heading)
    return Frame(index=k, time=t, detections=Detections(**columns), beacons=beacons)


def _empty(k: int, kind: str) -> Frame:
    return _frame(k, n_targets=0, kind=kind)


def _kind(name: str) -> str:
    return KINDS[name]


def _run(tracker: Any, frames: list[Frame]) -> list[list[Any]]:
    return [list(tracker.update(f)) for f in frames]


def _state(track: Any) -> tuple[float, ...]:
    """The reported box (px) or position (m) of a track, rounded."""
    value = track.xywh if track.position is None else track.position
    return tuple(np.round(np.asarray(value, dtype=float), 6).tolist())


def _summary(tracks: list[Any], order: np.ndarray | None = None) -> list[tuple[Any, ...]]:
    """(track id, status, state, original detection index) per track; ``order`` maps the indices back."""
    out = []
    for t in tracks:
        d = int(t.detection_index)
        if order is not None and d >= 0:
            d = int(order[d])
        out.append((int(t.track_id), t.status, _state(t), d))
    return out


# ---------------------------------------------------------------------------------------------


def test_every_tracker_has_a_kind() -> None:
    assert set(NAMES) <= set(KINDS), f"add {sorted(set(NAMES) - set(KINDS))} to KINDS in this file"
    assert set(NAMES) >= {"sort", "boxtrack", "deepsort", "diversort", "kalman_ha", "kalman_ha2", "jpda", "lstm"}


@pytest.mark.parametrize("name", _params("empty"))
def test_empty_frames_are_harmless(name: str) -> None:
    kind = _kind(name)
    tracker = make_tracker(name)
    assert list(tracker.update(_empty(0, kind))) == []
    for k in range(1, 8):
        tracker.update(_frame(k, kind=kind))
    after = list(tracker.update(_empty(8, kind)))
    assert all(int(t.detection_index) == -1 for t in after)
    tracker.update(_frame(9, kind=kind))  # and it carries on


@pytest.mark.parametrize("name", _params("empty_without_columns"))
def test_an_empty_frame_needs_no_columns(name: str) -> None:
    """``Detections.empty()`` (no position, heading or feature column) is an empty frame like any other."""
    kind = _kind(name)
    frames = [_frame(k, kind=kind) if k != 6 else _empty(k, kind) for k in range(10)]
    bare = [dataclasses.replace(f, detections=Detections.empty()) if k in (0, 6) else f for k, f in enumerate(frames)]
    frames[0] = _empty(0, kind)
    assert [_summary(f) for f in _run(make_tracker(name), bare)] == [
        _summary(f) for f in _run(make_tracker(name), frames)]


@pytest.mark.parametrize("name", _params("reset"))
def test_reset_gives_the_output_of_a_fresh_tracker(name: str) -> None:
    kind = _kind(name)
    frames = [_frame(k, kind=kind) if k != 12 else _empty(k, kind) for k in range(16)]
    fresh = _run(make_tracker(name), frames)
    used = make_tracker(name)
    _run(used, [_frame(k, n_targets=2, kind=kind) for k in range(20)])
    used.reset()
    again = _run(used, frames)
    assert [_summary(f) for f in again] == [_summary(f) for f in fresh]


@pytest.mark.parametrize("name", _params("copy"))
def test_a_copy_or_pickle_taken_mid_sequence_continues_as_the_original(name: str) -> None:
    kind = _kind(name)
    frames = [_frame(k, kind=kind) for k in range(12)]
    whole = [_summary(f) for f in _run(make_tracker(name), frames)]
    tracker = make_tracker(name)
    _run(tracker, frames[:4])
    for twin in (copy.deepcopy(tracker), pickle.loads(pickle.dumps(tracker))):
        assert [_summary(f) for f in _run(twin, frames[4:])] == whole[4:]
    assert [_summary(f) for f in _run(tracker, frames[4:])] == whole[4:]  # the copies shared no state


@pytest.mark.parametrize("name", _params("permuted"))
def test_detection_order_does_not_change_the_tracks(name: str) -> None:
    """The same tracks, up to renaming ids consistently, when each frame's detections come permuted."""
    kind = _kind(name)
    rng = np.random.default_rng(7)
    orders = [rng.permutation(N_TARGETS) for _ in range(20)]
    plain = _run(make_tracker(name), [_frame(k, kind=kind) for k in range(20)])
    permuted = _run(make_tracker(name), [_frame(k, kind=kind, order=orders[k]) for k in range(20)])
    id_map: dict[int, int] = {}
    for k in range(20):
        a = sorted(_summary(plain[k]), key=lambda r: (r[3], r[2]))
        b = sorted(_summary(permuted[k], orders[k]), key=lambda r: (r[3], r[2]))
        assert [r[1:] for r in a] == [r[1:] for r in b], f"frame {k}"
        for ra, rb in zip(a, b):
            assert id_map.setdefault(rb[0], ra[0]) == ra[0], f"frame {k}: track ids are not a consistent renaming"
    assert len(set(id_map.values())) == len(id_map) >= N_TARGETS


@pytest.mark.parametrize("name", _params("detection_index"))
def test_detection_index_points_at_the_detection_of_the_track(name: str) -> None:
    kind = _kind(name)
    tracker = make_tracker(name)
    checked = 0
    for k in range(20):
        frame = _frame(k, kind=kind, order=np.roll(np.arange(N_TARGETS), k))
        det = frame.detections
        tracks = list(tracker.update(frame))
        used = [int(t.detection_index) for t in tracks if int(t.detection_index) >= 0]
        assert len(used) == len(set(used)), f"frame {k}: a detection reported for two tracks"
        for t in tracks:
            d = int(t.detection_index)
            if d < 0:
                continue
            assert d < len(det)
            if name in IDENTIFIERS:
                assert det.heading is not None and t.heading == det.heading[d], f"frame {k}: track {t.track_id}"
                assert tracker.last_labels[d] == t.agent_id, f"frame {k}: track {t.track_id}"
            elif t.position is not None and det.position is not None:
                gaps = np.linalg.norm(det.position - np.asarray(t.position), axis=1)
                assert gaps[d] < 0.3 and d == int(np.argmin(gaps)), f"frame {k}: track {t.track_id}"
            else:
                assert t.xywh is not None and det.xywh is not None
                gaps = np.abs(det.xywh - np.asarray(t.xywh)).max(axis=1)
                assert gaps[d] < 10.0 and d == int(np.argmin(gaps)), f"frame {k}: track {t.track_id}"
            checked += 1
    assert checked >= N_TARGETS * 10  # the check was not vacuous


@pytest.mark.parametrize("name", _params("time_backwards"))
def test_time_going_backwards_is_refused(name: str) -> None:
    kind = _kind(name)
    tracker = make_tracker(name)
    for k in range(6):
        tracker.update(_frame(k, kind=kind))
    with pytest.raises(ValueError, match=r"time went backwards.*; a new sequence needs the tracker's reset\(\) first"):
        tracker.update(_frame(6, kind=kind, time_s=2 / FPS))
    # the refused frame leaves no trace: the next frames give what a tracker that never saw it gives
    untouched = make_tracker(name)
    _run(untouched, [_frame(k, kind=kind) for k in range(6)])
    later = [_frame(k, kind=kind) for k in range(6, 10)]
    assert [_summary(f) for f in _run(tracker, later)] == [_summary(f) for f in _run(untouched, later)]


@pytest.mark.parametrize("name", [n for n in NAMES if KINDS.get(n) == APPEARANCE])
def test_a_frame_refused_for_its_feature_length_leaves_no_trace(name: str) -> None:
    """Features of another length are refused before anything changes: the next frames (whose new look only
    the boxes can follow) give what a tracker that never saw the refused frame gives."""
    def frame(k: int, feature: np.ndarray) -> Frame:
        return dataclasses.replace(_frame(k, kind=APPEARANCE), detections=_frame(k, kind=APPEARANCE).detections
                                   .replace(feature=feature))

    refused, untouched = make_tracker(name), make_tracker(name)
    first = [_frame(k, kind=APPEARANCE) for k in range(6)]
    _run(refused, first)
    _run(untouched, first)
    with pytest.raises(ValueError, match="length 5"):
        refused.update(frame(6, np.eye(5)[:N_TARGETS]))
    later = [frame(k, np.eye(FEATURE_DIM)[N_TARGETS:2 * N_TARGETS]) for k in range(6, 10)]
    assert [_summary(f) for f in _run(refused, later)] == [_summary(f) for f in _run(untouched, later)]


@pytest.mark.parametrize("name", [n for n in NAMES if KINDS.get(n) == WORLD])
def test_a_frame_refused_for_an_unknown_agent_or_missing_columns_leaves_no_trace(name: str) -> None:
    refused, untouched = make_tracker(name), make_tracker(name)
    first = [_frame(k, kind=WORLD) for k in range(5)]
    _run(refused, first)
    _run(untouched, first)
    stranger = Beacons(agent_id=np.array([0, N_TARGETS]), t_sent=np.full(2, 5 / FPS - 0.02),
                       t_received=np.full(2, 5 / FPS), heading=np.zeros(2))
    with pytest.raises(ValueError, match="is no agent of this tracker"):
        refused.update(dataclasses.replace(_frame(5, kind=WORLD), beacons=stranger, time=5.5 / FPS))
    boxes_only = Detections(xywh=np.tile([10.0, 10.0, 5.0, 5.0], (2, 1)))
    with pytest.raises(ValueError, match="position"):
        refused.update(dataclasses.replace(_frame(5, kind=WORLD), detections=boxes_only, time=5.7 / FPS))
    later = [_frame(k, kind=WORLD) for k in range(5, 10)]
    assert [_summary(f) for f in _run(refused, later)] == [_summary(f) for f in _run(untouched, later)]


def test_a_frame_too_dense_for_jpda_leaves_no_trace() -> None:
    """JPDA refuses a cluster beyond its exact methods before it predicts or moves its clock: the next frames give
    what a tracker that never saw the refused frame gives."""
    refused, untouched = make_tracker("jpda", max_events=1), make_tracker("jpda", max_events=1)
    first = [_frame(k, kind=WORLD) for k in range(5)]
    _run(refused, first)
    _run(untouched, first)
    crowd = np.column_stack([2.05 + 0.002 * np.arange(25), np.full(25, -1.2)])  # 25 detections on one track
    dense = Detections(position=crowd, heading=np.zeros(25), score=np.full(25, 0.9))
    with pytest.raises(ValueError, match="exceeds the exact methods' limits"):
        refused.update(dataclasses.replace(_frame(5, kind=WORLD), detections=dense, time=5.5 / FPS))
    later = [_frame(k, kind=WORLD) for k in range(5, 10)]
    assert [_summary(f) for f in _run(refused, later)] == [_summary(f) for f in _run(untouched, later)]


def _deep_size(root: object) -> int:
    """Bytes of everything reachable from ``root`` through attributes and containers (arrays with their data)."""
    skip = (type, types.ModuleType, types.FunctionType, types.BuiltinFunctionType, types.MethodType)
    seen: set[int] = set()
    stack, total = [root], 0
    while stack:
        obj = stack.pop()
        if id(obj) in seen or isinstance(obj, skip):
            continue
        seen.add(id(obj))
        total += sys.getsizeof(obj)
        if isinstance(obj, dict):
            stack.extend(obj.keys())
            stack.extend(obj.values())
        elif isinstance(obj, (list, tuple, set, frozenset, collections.deque)):
            stack.extend(obj)
        elif hasattr(obj, "__dict__"):
            stack.append(vars(obj))
        stack.extend(getattr(obj, slot) for slot in getattr(type(obj), "__slots__", ()) if hasattr(obj, slot))
    return total


def _memory_growth(tracker: Any, detections: list[Detections]) -> tuple[int, int]:
    """Feed ``detections`` in turn for 10,000 frames; returns how many bytes the tracker's state grew
    from frame 1,000 to 9,000 and how many more bytes were held (tracemalloc) after frames 9,500-10,000."""

    def run(frames: range) -> None:
        for k in frames:
            tracker.update(Frame(index=k, time=k / FPS, detections=detections[k % len(detections)]))

    run(range(1000))
    state_1000 = _deep_size(tracker)
    run(range(1000, 9000))
    state_9000 = _deep_size(tracker)
    tracemalloc.start()
    try:
        run(range(9000, 9500))  # caches that fill once under tracing
        held_9500, _ = tracemalloc.get_traced_memory()
        run(range(9500, 10_000))
        held_10000, _ = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    return state_9000 - state_1000, held_10000 - held_9500


@pytest.mark.parametrize("name", _params("memory"))
def test_ten_thousand_frames_without_memory_growth(name: str) -> None:
    """The same two detections for 10,000 frames: the tracker's state keeps its size from frame 1,000
    on, and nothing else keeps growing."""
    kind = _kind(name)
    detections = [_frame(k, n_targets=2, kind=kind, move=False).detections for k in range(3)]
    state, held = _memory_growth(make_tracker(name), detections)
    assert state <= 1024, f"the tracker's state grew by {state} bytes from frame 1,000 to 9,000"
    assert held < 16 * 1024, f"{held} bytes more held after 500 more frames"


class _Leaky:
    """A tracker that keeps every frame's boxes (what the memory check must catch), in itself or,
    through ``keep``, somewhere its attributes do not reach."""

    def __init__(self, keep: Callable[[np.ndarray], None] | None = None) -> None:
        self.kept: list[np.ndarray] = []
        self.keep = self.kept.append if keep is None else keep

    def update(self, frame: Frame) -> list[Any]:
        self.keep(np.array(frame.detections.xywh))
        return []


def test_the_memory_check_catches_a_leak() -> None:
    detections = [_frame(0).detections]
    state, _ = _memory_growth(_Leaky(), detections)
    assert state > 8000 * 96  # every frame's (3, 4) array
    elsewhere: list[np.ndarray] = []
    state, held = _memory_growth(_Leaky(elsewhere.append), detections)
    assert state == 0 and held > 500 * 96


# ---------------------------------------------------------------------------------------------
# Bad parameter values


def _numeric_fields(name: str) -> list[tuple[str, type]]:
    config = tracker_class(name).Config
    hints = typing.get_type_hints(config)
    out = []
    for f in dataclasses.fields(config):
        args = [a for a in typing.get_args(hints[f.name]) if a is not type(None)] or [hints[f.name]]
        if args[0] in (int, float):
            out.append((f.name, args[0]))
    return out


def _unrejected(name: str, bad: Callable[[type], Any]) -> list[str]:
    """Numeric parameters whose bad value ``bad(type)`` builds a tracker, or fails without naming the field."""
    missed = []
    for field, kind in _numeric_fields(name):
        try:
            make_tracker(name, **{field: bad(kind)})
        except (ValueError, TypeError) as exc:
            if field not in str(exc):
                missed.append(f"{field} (message does not name it: {exc})")
        else:
            missed.append(field)
    return missed


@pytest.mark.parametrize("name", _params("nan"))
def test_nan_parameters_are_refused(name: str) -> None:
    assert _unrejected(name, lambda kind: math.nan) == []


@pytest.mark.parametrize("name", _params("negative"))
def test_negative_parameters_are_refused(name: str) -> None:
    assert _unrejected(name, lambda kind: kind(-1)) == []


@pytest.mark.parametrize("name", _params("wrong_type"))
def test_parameters_of_the_wrong_type_are_refused(name: str) -> None:
    assert _unrejected(name, lambda kind: "3") == []
