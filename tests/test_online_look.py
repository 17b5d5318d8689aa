"""The online closed set's slots re-assigned by the look learned while tracking (``--targets N --online`` on blobs)."""

from __future__ import annotations

import numpy as np
import pytest

from lookalike.pipeline.blob_detections import BlobRows
from lookalike.pipeline.blobs import with_look
from lookalike.trackers.offline.online_look import LookIdentities, SlotLooks, shape_lookup
from lookalike.trackers.registry import make_tracker
from lookalike.types import Detections, Frame, Tracks
from lookalike.vision.blob_shape import PART_SIZE
from tests.test_video_identities import _two_animals


def _online(rows: np.ndarray, shapes: np.ndarray, look: bool) -> np.ndarray:
    """``(frame, id, x)`` of the online closed set of 2 over ``rows``, with or without the look."""
    tracker = make_tracker("boxtrack", max_targets=2, n_init=2)
    found = BlobRows(rows, int(rows[:, 0].max()), shapes, np.full((len(rows), PART_SIZE), np.nan))
    if look:
        tracker = LookIdentities(tracker, 2, 25.0, shape_lookup(found.rows, found.shapes, found.frames))
    tracker.reset()
    out = []
    for k in range(found.frames):
        block = rows[rows[:, 0] == k + 1]
        tracks = tracker.update(Frame(index=k, time=k / 25.0, detections=Detections(xywh=block[:, 2:6])))
        out += [(k + 1, int(i), float(box[0])) for i, box in zip(tracks.id, tracks.xywh)]
    return np.array(out)


def _animal(result: np.ndarray, rows: np.ndarray, truth: np.ndarray) -> np.ndarray:
    """The true animal behind each result row: the detection nearest its box in its frame (0: a merged blob)."""
    out = np.zeros(len(result), int)
    for r, (frame, _, x) in enumerate(result):
        same = np.flatnonzero(rows[:, 0] == frame)
        out[r] = truth[same[np.argmin(np.abs(rows[same, 2] - x))]]
    return out


def test_after_two_look_alikes_touch_and_turn_back_the_look_gives_each_its_identity_again():
    rows, shapes, truth = _two_animals(bounce=True)
    for look in (False, True):
        result = _online(rows, shapes, look)
        animal = _animal(result, rows, truth)
        before = {i: set(animal[(result[:, 1] == i) & (result[:, 0] < 38) & (animal > 0)]) for i in (1, 2)}
        late = {i: set(animal[(result[:, 1] == i) & (result[:, 0] > 55) & (animal > 0)]) for i in (1, 2)}
        assert all(len(v) == 1 for v in (*before.values(), *late.values()))
        assert (before == late) == look  # motion alone carries each slot on through the other animal


def test_when_motion_was_right_the_look_changes_nothing():
    rows, shapes, _ = _two_animals(bounce=False)
    assert np.array_equal(_online(rows, shapes, True), _online(rows, shapes, False))


def test_ids_outside_the_slots_pass_unchanged_and_rows_without_a_blob_end_a_piece():
    looks = SlotLooks(2, 25.0)
    shape = np.zeros((3, 5))
    boxes = np.tile([0.0, 0.0, 10.0, 10.0], (3, 1))
    for _ in range(10):
        assert looks.update(np.array([1, 2, 7]), boxes, shape).tolist() == [1, 2, 7]
    assert set(looks.pieces) == {1, 2} and len(looks.pieces[1].shapes) == 10
    shape[0] = np.nan
    looks.update(np.array([1, 2, 7]), boxes, shape)
    assert set(looks.pieces) == {2} and len(looks.done) == 1


def test_shape_lookup_finds_each_box_in_its_frame_and_nan_elsewhere():
    rows = np.array([[1, -1, 0, 0, 5, 5, 1, -1, -1, -1], [2, -1, 3, 4, 5, 5, 1, -1, -1, -1],
                     [2, -1, 9, 9, 5, 5, 1, -1, -1, -1]], float)
    shapes = np.arange(6, dtype=float).reshape(3, 2)
    find = shape_lookup(rows, shapes, 3)
    got = find(1, np.array([[9, 9, 5, 5], [3, 4, 5, 5], [0, 0, 5, 5]], float))
    assert got[:2].tolist() == [[4, 5], [2, 3]] and np.isnan(got[2]).all()
    assert np.isnan(find(2, rows[:1, 2:6])).all() and np.isnan(find(7, rows[:1, 2:6])).all()


def test_only_an_online_closed_set_of_boxtrack_gets_the_look():
    def find(index: int, boxes: np.ndarray) -> np.ndarray:
        return np.zeros((len(boxes), 3))

    closed = make_tracker("boxtrack", max_targets=3)
    wrapped = with_look(closed, "boxtrack", 25.0, find)
    assert isinstance(wrapped, LookIdentities) and wrapped.config is closed.config
    assert with_look(make_tracker("boxtrack"), "boxtrack", 25.0, find).__class__.__name__ == "BoxTrack"
    assert not isinstance(with_look(make_tracker("sort"), "sort", 25.0, find), LookIdentities)
    tracks = wrapped.update(Frame(index=0, time=0.0, detections=Detections.empty()))
    assert isinstance(tracks, Tracks) and len(tracks) == 0


@pytest.mark.parametrize("n", [1, 3])
def test_a_wrapped_tracker_starts_again_on_reset(n):
    tracker = LookIdentities(make_tracker("boxtrack", max_targets=n), n, 25.0, lambda i, b: np.zeros((len(b), 2)))
    det = Detections(xywh=np.array([[10.0, 10.0, 8.0, 8.0]]))
    for k in range(3):
        tracker.update(Frame(index=k, time=k / 25.0, detections=det))
    assert tracker.looks.frame == 3
    tracker.reset()
    assert tracker.looks.frame == 0 and not tracker.looks.pieces


def test_the_online_pass_over_rows_re_assigns_slots_as_the_command_does():
    from lookalike.trackers.offline.closed_set import online_rows

    rows, shapes, truth = _two_animals(bounce=True)
    plain = online_rows(rows, 25.0, reported=True, max_targets=2, n_init=2)
    looked = online_rows(rows, 25.0, reported=True, shapes=shapes, max_targets=2, n_init=2)
    assert np.array_equal(looked[:, [0, 1, 2]], _online(rows, shapes, True))
    assert not np.array_equal(plain[:, 1], looked[:, 1]) and np.array_equal(plain[:, 2:6], looked[:, 2:6])


def test_memory_stays_bounded_on_a_long_run(monkeypatch):
    from lookalike.trackers.offline import online_look

    monkeypatch.setattr(online_look, "MAX_PIECES", 5)
    monkeypatch.setattr(online_look, "MAX_PIECE_ROWS", 12)
    looks = SlotLooks(1, 25.0)
    box, alone, broken = np.array([[0.0, 0.0, 10.0, 10.0]]), np.zeros((1, 4)), np.full((1, 4), np.nan)
    for _ in range(30):
        for _ in range(20):
            looks.update(np.array([1]), box, alone)
        assert len(looks.pieces[1].shapes) == 12
        looks.update(np.array([1]), box, broken)
    assert len(looks.done) == 5 and all(len(s) == 12 for _, s, _ in looks.done)


def test_rows_on_their_own_animals_identity_get_a_positive_look_margin():
    rows, shapes, truth = _two_animals(bounce=True)
    found = BlobRows(rows, int(rows[:, 0].max()), shapes, np.full((len(rows), PART_SIZE), np.nan))
    tracker = LookIdentities(make_tracker("boxtrack", max_targets=2, n_init=2), 2, 25.0,
                             shape_lookup(found.rows, found.shapes, found.frames), keep_margins=True)
    reported = 0
    for k in range(found.frames):
        block = rows[rows[:, 0] == k + 1]
        reported += len(tracker.update(Frame(index=k, time=k / 25.0, detections=Detections(xywh=block[:, 2:6]))))
    margins = tracker.margin_rows()
    assert len(margins) == reported and set(np.unique(margins[:, 1])) == {1, 2}
    judged = margins[~np.isnan(margins[:, 2])]
    assert len(judged) > 20 and judged[:, 0].min() > 43  # only once both animals have a finished piece
    assert np.all(judged[:, 2] > 0) and np.all(np.abs(judged[:, 2]) <= 3.0)
    assert not LookIdentities(make_tracker("boxtrack", max_targets=2), 2, 25.0).margin_rows().size
