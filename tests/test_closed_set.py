"""Offline closed-set identity (trackers.closed_set) on scenes built to break it."""

from __future__ import annotations

import numpy as np
import pytest

from lookalike.eval import evaluate_sequence
from lookalike.io import MotTable
from lookalike.trackers.offline.closed_set import (
    ClosedSetConfig,
    assign_identities,
    link_costs,
    online_rows,
    split_tracklets,
    track_closed_set,
)

SIZE = 20.0
FPS = 10.0


def _rows(paths: list[np.ndarray], hidden: list[np.ndarray], noise: float, seed: int) -> tuple[np.ndarray, np.ndarray]:
    """Ground truth and detection rows of targets following ``paths`` ((frames, 2) centres, px);
    ``hidden[i]`` marks the frames where target i is not detected."""
    rng = np.random.default_rng(seed)
    gt, det = [], []
    for tid, (p, h) in enumerate(zip(paths, hidden), 1):
        for k, (cx, cy) in enumerate(p):
            gt.append([k + 1, tid, cx - SIZE / 2, cy - SIZE / 2, SIZE, SIZE, 1, -1, -1, -1])
            if not h[k]:
                nx, ny = rng.normal(0, noise, 2)
                det.append([k + 1, -1, cx - SIZE / 2 + nx, cy - SIZE / 2 + ny, SIZE, SIZE, 0.9, -1, -1, -1])
    return np.array(gt), np.array(det)


def _crossing(frames: int = 60, hidden: int = 8, angle: float = 0.6, speed: float = 4.0, seed: int = 0):
    """Two targets crossing in an X, both undetected for ``hidden`` frames around the crossing."""
    t = np.arange(frames) - frames / 2
    centre = np.array([200.0, 200.0])
    paths = [centre + t[:, None] * np.array([np.cos(angle), s * np.sin(angle)]) * speed for s in (1, -1)]
    gap = np.abs(t) <= hidden / 2
    return _rows(paths, [gap, gap], 1.0, seed)


def _score(gt: np.ndarray, rows: np.ndarray) -> dict[str, float]:
    return evaluate_sequence(MotTable.from_rows(gt), MotTable.from_rows(rows), num_frames=int(gt[:, 0].max()))


def test_offline_undoes_the_online_swap_at_a_crossing() -> None:
    gt, det = _crossing(hidden=8)
    online = online_rows(det, FPS, 60, max_targets=2)
    assert _score(gt, online)["IDSW"] > 0  # the scene really breaks the online closed set
    offline = track_closed_set(det, 2, FPS, n_frames=60)
    s = _score(gt, offline)
    assert s["IDSW"] == 0
    assert s["IDF1"] > 0.97
    assert set(np.unique(offline[:, 1])) == {1, 2}


@pytest.mark.parametrize("angle", [0.3, 0.6, 1.0])
@pytest.mark.parametrize("hidden", [2, 6, 12])
def test_crossings_of_any_angle_and_length_keep_identities(angle: float, hidden: int) -> None:
    gt, det = _crossing(hidden=hidden, angle=angle)
    assert _score(gt, track_closed_set(det, 2, FPS, n_frames=60))["IDSW"] == 0


def test_long_side_by_side_crossing() -> None:
    """Two targets run side by side (touching) for 20 frames at the same speed, then part."""
    frames = 80
    k = np.arange(frames, dtype=float)
    x = 50 + 4 * k
    lane = np.clip(np.abs(k - 40) - 10, 0, None) * 2.0  # apart, together for frames 30..50, apart again
    paths = [np.column_stack([x, 200 - 6 - lane]), np.column_stack([x, 200 + 6 + lane])]
    gt, det = _rows(paths, [np.zeros(frames, bool)] * 2, 0.5, 1)
    s = _score(gt, track_closed_set(det, 2, FPS, n_frames=frames))
    assert s["IDSW"] == 0 and s["IDF1"] > 0.95


def test_two_targets_missing_at_once_are_relinked_by_motion() -> None:
    """Three targets on parallel diagonals; two of them vanish for 10 frames at the same time."""
    frames = 70
    k = np.arange(frames, dtype=float)
    paths = [np.column_stack([40 + 4 * k, 100 + 30 * i + 1.0 * k]) for i in range(3)]
    gone = (k >= 30) & (k < 40)
    gt, det = _rows(paths, [gone, gone, np.zeros(frames, bool)], 1.0, 2)
    out = track_closed_set(det, 3, FPS, n_frames=frames)
    s = _score(gt, out)
    assert s["IDSW"] == 0 and s["IDF1"] > 0.97
    assert len(np.unique(out[:, 1])) == 3


def test_a_false_blob_standing_still_is_not_given_an_identity() -> None:
    """Three moving targets; a static false blob sits away from their paths while one target is hidden."""
    frames = 80
    k = np.arange(frames, dtype=float)
    paths = [np.column_stack([40 + 4 * k, 100 + 60 * i + 10 * np.sin(k / 8 + i)]) for i in range(3)]
    hidden = [np.zeros(frames, bool), (k >= 30) & (k < 50), np.zeros(frames, bool)]
    gt, det = _rows(paths, hidden, 1.0, 3)
    still = [[f, -1, 300, 400, SIZE, SIZE, 0.9, -1, -1, -1] for f in range(25, 56)]
    det = np.vstack([det, np.array(still, float)])
    out = track_closed_set(det, 3, FPS, n_frames=frames)
    assert not np.any(np.hypot(out[:, 2] - 300, out[:, 3] - 400) < 5)  # the blob is clutter
    s = _score(gt, out)
    assert s["IDSW"] == 0 and s["IDF1"] > 0.95


def test_ids_are_one_to_n_and_tracklets_never_overlap_in_an_identity() -> None:
    gt, det = _crossing(hidden=6)
    rng = np.random.default_rng(5)
    clutter = np.array([[f, -1, *rng.uniform(0, 400, 2), SIZE, SIZE, 0.9, -1, -1, -1] for f in range(1, 61, 3)])
    out = track_closed_set(np.vstack([det, clutter]), 2, FPS, n_frames=60)
    assert set(np.unique(out[:, 1]).astype(int)) <= {1, 2}
    pairs = out[:, :2].astype(int)
    assert len(np.unique(pairs, axis=0)) == len(pairs)  # one row per identity and frame


def test_split_tracklets_cuts_at_gaps_and_jumps() -> None:
    frames = [*range(1, 11), *range(12, 21)]
    rows = np.array([[f, 1, 5.0 * f, 0, 10, 10, 1, -1, -1, -1] for f in frames]
                    + [[f, 1, 500.0 + 5 * f, 0, 10, 10, 1, -1, -1, -1] for f in range(21, 26)], dtype=float)
    pieces = split_tracklets(rows)
    assert [(t.first, t.last) for t in pieces] == [(1, 10), (12, 20), (21, 25)]


def test_bad_input_is_refused() -> None:
    with pytest.raises(ValueError, match="n_targets"):
        assign_identities(np.zeros((0, 10)), 0, FPS)
    with pytest.raises(ValueError, match="rows"):
        assign_identities(np.zeros((3, 4)), 2, FPS)
    with pytest.raises(ValueError, match="candidates"):
        ClosedSetConfig(candidates=0)
    assert assign_identities(np.zeros((0, 10)), 2, FPS).shape == (0, 10)


@pytest.mark.parametrize("column, value", [(4, np.nan), (2, np.inf), (0, 0.0), (0, 2.5)])
def test_a_row_with_a_nan_box_or_a_bad_frame_is_refused_naming_it(column: int, value: float) -> None:
    # a NaN width came out as NaN rows; frame 0 or 2.5 was dropped without a word
    _, det = _crossing(frames=12, hidden=0)
    det[3, column] = value
    with pytest.raises(ValueError, match=r"rows\[3\]: needs a whole frame >= 1 and a finite id and box"):
        track_closed_set(det, 2, FPS)
    result = online_rows(np.delete(det, 3, axis=0), FPS)
    result[3, column] = value
    with pytest.raises(ValueError, match=r"rows\[3\]"):
        assign_identities(result, 2, FPS)


def test_rows_past_n_frames_are_refused_not_dropped() -> None:
    # frames after n_frames were left out of the result without a word
    _, det = _crossing(frames=12, hidden=0)
    with pytest.raises(ValueError, match=r"det_rows: frame 12 is past n_frames \(10\)"):
        track_closed_set(det, 2, FPS, n_frames=10)
    assert track_closed_set(det, 2, FPS, n_frames=14)[:, 0].max() == 12  # a longer sequence is fine


@pytest.mark.parametrize("rate", [0.0, -1.0, float("nan"), float("inf")])
def test_a_frame_rate_not_above_zero_or_not_finite_is_refused(rate: float) -> None:
    # 0 ended in ZeroDivisionError, NaN in a message about Frame.time, infinity was taken
    _, det = _crossing(frames=12, hidden=0)
    for call in (lambda: track_closed_set(det, 2, rate), lambda: assign_identities(online_rows(det, FPS), 2, rate)):
        with pytest.raises(ValueError, match="frame_rate must be > 0 frames/s"):
            call()


def test_a_broken_track_stays_one_identity_when_identities_are_spare() -> None:
    """Two targets, N = 3: one target's track breaks for 6 frames; starting a spare identity mid-video costs
    ``edge_cost``, so the motion-consistent link wins and the target keeps one identity."""
    frames = 60
    k = np.arange(frames, dtype=float)
    paths = [np.column_stack([40 + 4 * k, 100 + 0 * k]), np.column_stack([40 + 4 * k, 300 + 0 * k])]
    gone = (k >= 28) & (k < 34)
    _, det = _rows(paths, [gone, np.zeros(frames, bool)], 0.3, 6)
    rows = np.column_stack([det[:, 0], np.where(det[:, 3] < 200, np.where(det[:, 0] < 30, 1, 3), 2), det[:, 2:]])
    out = assign_identities(rows, 3, FPS)
    assert len(np.unique(out[:, 1])) == 2
    split = assign_identities(rows, 3, FPS, ClosedSetConfig(edge_cost=0.0))
    assert len(np.unique(split[:, 1])) == 3  # without it, the spare identity is free


def test_a_stray_row_far_past_an_identity_end_is_not_bridged() -> None:
    """A single detection 100 frames after a target's last row is not placed on it (no 100-frame fill)."""
    track = np.array([[f, 1, 100 + 2 * f, 100, SIZE, SIZE, 1, -1, -1, -1] for f in range(1, 41)], float)
    stray = np.array([[140, 2, 180, 100, SIZE, SIZE, 1, -1, -1, -1]], float)
    out = assign_identities(np.vstack([track, stray]), 1, FPS)
    assert out[:, 0].max() == 40


def test_boxes_are_smoothed_along_an_identity() -> None:
    """A one-frame detector error is removed from a still target; a steady motion is kept."""
    rows = np.array([[f, 1, 100.0, 100.0, SIZE, SIZE, 1, -1, -1, -1] for f in range(1, 61)])
    rows[30, 2:4] += 8.0
    out = assign_identities(rows, 1, FPS)
    assert np.abs(out[:, 2:4] - 100.0).max() < 1e-9


def test_link_costs_scored_in_blocks_are_those_of_one_block(monkeypatch: pytest.MonkeyPatch) -> None:
    """Many tracklets: ends scored a block at a time (memory linear in the tracklets) give the same links."""
    import lookalike.trackers.offline.tracklets as tracklets_module

    rng = np.random.default_rng(4)
    rows = []
    for tid in range(1, 121):
        start = int(rng.integers(1, 150))
        pos, vel = rng.uniform(0, 400, 2), rng.normal(0, 2, 2)
        for f in range(start, start + int(rng.integers(5, 40))):
            pos = pos + vel
            rows.append([f, tid, *(pos - 5), 10, 10, 1, -1, -1, -1])
    pieces = split_tracklets(np.array(rows, dtype=float), ClosedSetConfig())
    whole = link_costs(pieces, 25.0)
    monkeypatch.setattr(tracklets_module, "LINK_BLOCK", 300)  # a few ends per block
    blocked = link_costs(pieces, 25.0)
    assert len(whole[0]) > 100
    assert all(np.array_equal(a, b) for a, b in zip(whole, blocked))
