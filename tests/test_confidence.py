"""The per-row identity confidence and its doubtful ranges (lookalike.trackers.offline.confidence)."""

from __future__ import annotations

import numpy as np
import pytest

from lookalike.trackers.offline.confidence import (
    FEATURES,
    assignment_confidence,
    by_frame_and_id,
    describe_ranges,
    doubtful_ranges,
    row_features,
)

FPS = 10.0


def _rows(track: dict[int, list[tuple[int, float, float]]], size: float = 20.0) -> np.ndarray:
    """MOTChallenge rows from ``{id: [(frame, centre x, centre y), ...]}`` with square boxes of ``size`` px."""
    out = [[f, i, x - size / 2, y - size / 2, size, size, 1, -1, -1, -1] for i, pts in track.items() for f, x, y in pts]
    return np.array(out, float).reshape(-1, 10)


def _crossing(frames: int = 200, meet: int = 100) -> dict[int, list[tuple[int, float, float]]]:
    """Two look-alikes crossing at ``meet`` on one line, and a third far away, all seen in every frame."""
    return {1: [(f, 100.0 + 3 * (f - meet), 100.0) for f in range(1, frames + 1)],
            2: [(f, 100.0 - 3 * (f - meet), 100.0) for f in range(1, frames + 1)],
            3: [(f, 2000.0, 2000.0 + f) for f in range(1, frames + 1)]}


def test_probabilities_in_unit_interval_and_finite() -> None:
    rng = np.random.default_rng(0)
    rows = np.column_stack([rng.integers(1, 50, 300), rng.integers(1, 20, 300), rng.uniform(0, 500, (300, 2)),
                            rng.uniform(0, 40, (300, 2)), np.ones((300, 4))])  # zero-size boxes included
    rows = rows[np.unique(rows[:, :2], axis=0, return_index=True)[1]]  # one row per (frame, id)
    p = assignment_confidence(rows, FPS)
    assert p.shape == (len(rows),)
    assert np.isfinite(p).all() and (p >= 0).all() and (p <= 1).all()
    assert np.isfinite(row_features(rows, FPS)).all()


def test_row_order_does_not_matter() -> None:
    rows = _rows(_crossing(60, 30))
    order = np.random.default_rng(1).permutation(len(rows))
    np.testing.assert_allclose(assignment_confidence(rows[order], FPS), assignment_confidence(rows, FPS)[order])


def test_crossing_rows_less_confident_than_isolated_rows() -> None:
    rows = _rows(_crossing())
    p = assignment_confidence(rows, FPS)
    near = (rows[:, 0] >= 95) & (rows[:, 0] <= 105)
    crossing = p[near & (rows[:, 1] != 3)]
    isolated = p[near & (rows[:, 1] == 3)]
    assert crossing.max() < isolated.min()


def test_ranges_cover_a_swap_that_breaks_into_fragments() -> None:
    """At the crossing the tracker loses target B: id 2 ends, short id 4 follows B's jittery boxes (merged with A's
    every other frame), id 5 takes B on. The fragment is doubtful; the steady identity far away is not."""
    track = _crossing()
    b = track.pop(2)
    track[2] = [p for p in b if p[0] <= 96]
    track[5] = [p for p in b if p[0] >= 104]
    rows = _rows(track)
    fragment = _rows({4: [p for p in b if 98 <= p[0] <= 102]})
    fragment[1::2, 4] *= 2  # a box covering both look-alikes every other frame
    rows = np.vstack([rows, fragment])
    ranges = doubtful_ranges(rows, assignment_confidence(rows, FPS), FPS)
    assert ranges.get(4) == [(98, 102)]
    assert 3 not in ranges
    assert "id 4 frames 98-102" in describe_ranges(ranges)


def test_empty_and_one_row() -> None:
    empty = np.zeros((0, 10))
    assert row_features(empty, FPS).shape == (0, len(FEATURES))
    assert assignment_confidence(empty, FPS).shape == (0,)
    assert doubtful_ranges(empty, np.zeros(0), FPS) == {}
    assert describe_ranges({}) == "doubtful: none"
    p = assignment_confidence(_rows({7: [(5, 10.0, 10.0)]}), FPS)
    assert p.shape == (1,) and 0.0 <= p[0] <= 1.0


def test_ranges_merge_frames_at_most_a_second_apart() -> None:
    rows = _rows({1: [(f, 0.0, 0.0) for f in range(1, 41)]})
    conf = np.ones(len(rows))
    conf[[2, 3, 10, 30]] = 0.1  # frames 3, 4, 11 (7 frames on: merged at 10 frames/s) and 31
    assert doubtful_ranges(rows, conf, FPS) == {1: [(3, 11), (31, 31)]}
    assert describe_ranges({1: [(3, 11), (31, 31)]}) == "doubtful: id 1 frames 3-11, 31"


def test_description_is_capped() -> None:
    ranges = {i: [(10 * k, 10 * k + i) for k in range(1, 7)] for i in range(1, 12)}
    line = describe_ranges(ranges, max_ids=3, max_ranges=2)
    assert line.count("id ") == 3 and "(+4 more)" in line and line.endswith("; 8 more ids")
    assert "id 11 " in line and "id 1 " not in line  # the ids with the most doubtful frames


def test_bad_input_is_refused() -> None:
    with pytest.raises(ValueError, match="frame_rate"):
        assignment_confidence(np.zeros((1, 10)), 0.0)
    with pytest.raises(ValueError, match="rows"):
        row_features(np.zeros((3, 4)), FPS)
    with pytest.raises(ValueError, match="confidence"):
        doubtful_ranges(np.zeros((2, 10)), np.zeros(3), FPS)
    with pytest.raises(ValueError, match="confidence: NaN at row 1"):  # (NaN is below no threshold: never doubtful)
        doubtful_ranges(np.ones((2, 10)), np.array([0.9, np.nan]), FPS)


def test_the_look_margin_moves_the_confidence_its_way_and_zero_leaves_it() -> None:
    rows = _rows(_crossing(60, 30))
    plain = assignment_confidence(rows, FPS)
    np.testing.assert_allclose(assignment_confidence(rows, FPS, look=np.zeros(len(rows))), plain)
    look = np.where(rows[:, 1] == 1, 2.0, np.where(rows[:, 1] == 2, -2.0, 0.0))
    p = assignment_confidence(rows, FPS, look=look)
    assert np.all(p[rows[:, 1] == 1] > plain[rows[:, 1] == 1]) and np.all(p[rows[:, 1] == 2] < plain[rows[:, 1] == 2])
    np.testing.assert_allclose(p[rows[:, 1] == 3], plain[rows[:, 1] == 3])
    with pytest.raises(ValueError, match="look"):
        assignment_confidence(rows, FPS, look=np.zeros(3))


def test_values_found_by_frame_and_id() -> None:
    rows = _rows({1: [(1, 0, 0), (2, 0, 0)], 7: [(1, 50, 50), (3, 50, 50)]})
    keyed = np.array([[2, 1, 0.5], [1, 7, -1.5], [3, 7, np.nan], [9, 1, 4.0]])
    by_row = dict(zip(map(tuple, rows[:, :2].astype(int).tolist()), np.nan_to_num(by_frame_and_id(rows, keyed), nan=9)))
    assert by_row == {(1, 1): 9, (2, 1): 0.5, (1, 7): -1.5, (3, 7): 9}
    assert np.isnan(by_frame_and_id(rows, np.zeros((0, 3)))).all()
    odd = np.array([[1, -1, 0, 0, 1, 1], [1, 5, 0, 0, 1, 1], [2, -1, 0, 0, 1, 1]], float)  # ids of any sign
    np.testing.assert_array_equal(by_frame_and_id(odd, np.array([[2, -1, 3.0], [1, 5, 4.0]])), [np.nan, 4.0, 3.0])

