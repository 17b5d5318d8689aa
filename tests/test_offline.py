"""trackers.offline: linking broken tracks and filling short gaps in a finished result."""

from __future__ import annotations

import numpy as np
import pytest

from lookalike.trackers.offline.gap_fill import (
    OfflineConfig,
    fill_gaps,
    link_tracks,
    postprocess,
    smooth_boxes,
)


def _rows(track_id: int, frames: range | list[int], x0: float = 100.0, vx: float = 5.0) -> np.ndarray:
    """Rows of one box 40x80 px moving ``vx`` px/frame from ``x0`` (at frame 1)."""
    f = np.asarray(list(frames), dtype=float)
    rows = np.full((len(f), 10), -1.0)
    rows[:, 0], rows[:, 1] = f, track_id
    rows[:, 2], rows[:, 3], rows[:, 4], rows[:, 5], rows[:, 6] = x0 + vx * (f - 1), 50.0, 40.0, 80.0, 1.0
    return rows


def test_fill_gaps_interpolates_short_gaps_only() -> None:
    rows = np.vstack([_rows(1, [1, 2, 3, 7, 8]), _rows(2, [1, 20])])
    out = fill_gaps(rows, max_gap=3)
    one = out[out[:, 1] == 1]
    assert one[:, 0].tolist() == [1, 2, 3, 4, 5, 6, 7, 8]
    np.testing.assert_allclose(one[:, 2], 100 + 5 * (one[:, 0] - 1))  # linear motion is recovered exactly
    assert out[out[:, 1] == 2][:, 0].tolist() == [1, 20]  # 18 missing frames > max_gap: left alone
    assert np.all(np.diff(out[:, 0]) >= 0)  # sorted by frame
    assert len(fill_gaps(rows, max_gap=0)) == len(rows)


def test_link_tracks_joins_a_continuation_not_a_stranger() -> None:
    first = _rows(1, range(1, 11))
    continuation = _rows(2, range(14, 25))  # same walker after a 3-frame gap
    stranger = _rows(3, range(14, 25), x0=600.0)  # starts at the same time, far away
    rows = np.vstack([first, continuation, stranger])
    out = link_tracks(rows, frame_rate=10.0, config=OfflineConfig(link_gap_s=1.0, link_distance=1.0))
    assert set(out[out[:, 0] >= 14][:, 1]) == {1, 3}
    assert (out[:, 1] == 1).sum() == 10 + 11
    # the gap is longer than link_gap_s: nothing is linked
    out = link_tracks(rows, frame_rate=10.0, config=OfflineConfig(link_gap_s=0.2))
    np.testing.assert_array_equal(out[:, 1], rows[:, 1])


def test_link_tracks_never_links_tracks_that_overlap_in_time_or_differ_in_size() -> None:
    a, b = _rows(1, range(1, 11)), _rows(2, range(10, 20), x0=145.0)  # overlap at frame 10
    out = link_tracks(np.vstack([a, b]), frame_rate=10.0, config=OfflineConfig(link_gap_s=2.0, link_distance=5.0))
    assert set(out[:, 1]) == {1, 2}
    big = _rows(2, range(13, 20))
    big[:, 4:6] *= 2.5
    out = link_tracks(np.vstack([a, big]), frame_rate=10.0, config=OfflineConfig(link_gap_s=2.0, link_distance=5.0))
    assert set(out[:, 1]) == {1, 2}


def test_postprocess_links_chains_then_fills() -> None:
    rows = np.vstack([_rows(5, range(1, 6)), _rows(9, range(8, 13)), _rows(7, range(15, 20))])
    out = postprocess(rows, frame_rate=10.0, config=OfflineConfig(link_gap_s=0.5, fill_gap_s=0.5))
    assert set(out[:, 1]) == {5}  # 5 -> 9 -> 7 is one chain keeping the first id
    assert out[:, 0].tolist() == list(range(1, 20))


def test_bad_input_is_rejected() -> None:
    with pytest.raises(ValueError, match="rows"):
        fill_gaps(np.zeros((3, 4)), 2)
    with pytest.raises(ValueError, match="frame_rate"):
        postprocess(_rows(1, [1, 2]), frame_rate=0.0)
    with pytest.raises(ValueError, match="scale"):
        OfflineConfig(scale=0.5)
    with pytest.raises(ValueError, match="fill_gap_s"):
        OfflineConfig(fill_gap_s=-1.0)
    with pytest.raises(ValueError, match="max_gap"):
        fill_gaps(_rows(1, [1, 2]), -1)


def test_smooth_boxes_removes_outliers_and_keeps_a_steady_motion() -> None:
    moving = _rows(1, range(1, 31))
    np.testing.assert_allclose(smooth_boxes(moving, 5)[2:-2, 2:6], moving[2:-2, 2:6])  # ends are held
    still = _rows(2, range(1, 31), vx=0.0)
    noisy = still.copy()
    noisy[10, 2:4] += 30.0  # one wrong box
    np.testing.assert_allclose(smooth_boxes(noisy, 5)[:, 2:6], still[:, 2:6])
    np.testing.assert_array_equal(smooth_boxes(noisy, 1), noisy)
    both = np.vstack([moving, noisy])
    np.testing.assert_allclose(smooth_boxes(both, 5)[30:, 2:6], still[:, 2:6])  # ids never mix
