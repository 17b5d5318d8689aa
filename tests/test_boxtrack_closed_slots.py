"""Closed-set slots (``max_targets``): scenes built to lose a slot for good, and the rules that keep it.

A lost slot's box shape is frozen while it coasts, its recovery gate grows with the time lost, and a
slot lost longer than ``max_age_s`` is re-assigned to a confident detection that persisted
``n_init`` frames where no slot recovered it."""

from __future__ import annotations

import numpy as np

from lookalike.trackers import make_tracker
from lookalike.trackers.parts.closed_slots import ClosedSlots
from lookalike.trackers.parts.table import TrackTable
from lookalike.types import Detections, Frame


def _frame(k: int, boxes: list[list[float]], fps: float = 10.0) -> Frame:
    xywh = np.array(boxes, dtype=float).reshape(-1, 4)
    return Frame(index=k, time=k / fps, detections=Detections(xywh=xywh, score=np.full(len(xywh), 0.95)))


def _ids(tracks) -> dict[int, np.ndarray]:  # type: ignore[no-untyped-def]
    return {int(t.track_id): np.asarray(t.xywh) for t in tracks}


def test_a_coasting_slot_keeps_its_shape() -> None:
    # A target shrinking by 2 px a frame, then missing for 3 s: its box must not keep shrinking.
    tracker = make_tracker("boxtrack", max_targets=2)
    still = [400.0, 100.0, 30.0, 60.0]
    for k in range(10):
        tracker.update(_frame(k, [[100.0, 100.0, 60.0 - 2 * k, 120.0 - 4 * k], still]))
    for k in range(10, 40):
        tracker.update(_frame(k, [still]))
    t = tracker._tracks
    lost = int(np.flatnonzero(t.unseen_s > 0)[0])
    w, h = t.mean[lost, 2:4]
    assert 35 <= w <= 50 and 75 <= h <= 100  # the size at loss (42 x 84), not shrunk to nothing


def test_a_target_back_far_away_after_long_gets_its_slot_back() -> None:
    tracker = make_tracker("boxtrack", max_targets=2)
    a, b = [100.0, 100.0, 20.0, 40.0], [500.0, 100.0, 20.0, 40.0]
    for k in range(10):
        tracker.update(_frame(k, [a, b]))
    for k in range(10, 60):  # b missing 5 s
        tracker.update(_frame(k, [a]))
    seen: set[int] = set()
    far = [500.0, 700.0, 20.0, 40.0]  # 15 heights away from where b was lost
    for k in range(60, 80):
        seen |= set(_ids(tracker.update(_frame(k, [a, far]))))
    last = _ids(tracker.update(_frame(80, [a, far])))
    assert seen <= {1, 2} and len(last) == 2  # no third identity; both reported


def test_two_missing_at_once_both_come_back() -> None:
    tracker = make_tracker("boxtrack", max_targets=3)
    boxes = [[100.0, 100.0, 20.0, 40.0], [400.0, 100.0, 20.0, 40.0], [700.0, 100.0, 20.0, 40.0]]
    for k in range(10):
        tracker.update(_frame(k, boxes))
    for k in range(10, 50):  # two of three missing 4 s
        tracker.update(_frame(k, boxes[:1]))
    back = [boxes[0], [400.0, 900.0, 20.0, 40.0], [700.0, 900.0, 20.0, 40.0]]
    seen: set[int] = set()
    for k in range(50, 70):
        seen |= set(_ids(tracker.update(_frame(k, back))))
    assert seen == {1, 2, 3}
    assert len(_ids(tracker.update(_frame(70, back)))) == 3


def test_the_recovery_gate_grows_with_time_lost() -> None:
    slots = ClosedSlots(4, distance=4.0, growth=1.0, refill_s=1.0)
    assert slots.gate(np.array([0.0, 2.0])).ravel().tolist() == [4.0, 6.0]


def test_room_counts_free_and_long_lost_slots_less_waiting_candidates() -> None:
    table = TrackTable(8)
    table.add(np.zeros((3, 8)), np.zeros((3, 8, 8)), confirmed=True)
    slots = ClosedSlots(3, distance=4.0, growth=1.0, refill_s=1.0)
    assert slots.room(table) == 0
    table.unseen_s[0] = 1.5  # lost long: its slot may be re-filled
    assert slots.room(table) == 1
    table.add(np.zeros((1, 8)), np.zeros((1, 8, 8)), hits=1)  # a candidate waiting
    assert slots.room(table) == 0


def test_the_gate_grows_with_the_targets_typical_speed_and_sizes_ignore_turning() -> None:
    table = TrackTable(8)
    mean = np.zeros((2, 8))
    mean[:, 2:4] = [10.0, 40.0]  # size sqrt(10*40) = 20 px
    mean[:, 4] = 4.0  # 4 px/frame = 0.2 sizes/frame = 2 sizes/s at 10 frames/s
    table.add(mean, np.zeros((2, 8, 8)), confirmed=True)
    slots = ClosedSlots(2, distance=8.0, growth=1.0, refill_s=2.0)
    slots.observe_speed(table, np.array([True, True]), dt=0.1)
    assert slots.speed == np.float64(2.0)
    assert slots.gate(np.array([1.0])).ravel().tolist() == [12.0]  # 8 + 2 x 2 sizes/s x 1 s
    turned = ClosedSlots.squared(np.array([[0.0, 0.0, 40.0, 10.0]]))
    assert turned[0, 2:].tolist() == [20.0, 20.0] == ClosedSlots.squared(mean[:1, :4])[0, 2:].tolist()


def test_reset_forgets_the_typical_speed_of_the_previous_sequence() -> None:
    # Targets fast in the first sequence; in the second one a slow target is lost for 1 s and comes back 15
    # sizes away: a fresh tracker's gate (from the slow speed) does not reach it, the previous speed's would.
    def scene(speed: float, lost: range = range(0), jump: float = 0.0) -> list[Frame]:
        frames = []
        for k in range(40):
            boxes = [[50.0 + speed * k, 100.0, 20.0, 20.0], [400.0 + speed * k + (jump if k >= lost.stop else 0.0),
                                                               100.0, 20.0, 20.0]]
            frames.append(_frame(k, boxes[:1] if k in lost else boxes))
        return frames

    second = scene(1.0, lost=range(10, 20), jump=300.0)
    fresh = make_tracker("boxtrack", max_targets=2)
    expected = [_ids(fresh.update(f)) for f in second]
    used = make_tracker("boxtrack", max_targets=2)
    for f in scene(60.0):
        used.update(f)
    used.reset()
    got = [_ids(used.update(f)) for f in second]
    assert [sorted(g) for g in got] == [sorted(e) for e in expected]
    assert all(np.allclose(g[i], e[i]) for g, e in zip(got, expected) for i in e)
