import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from lookalike import Detections, Frame, TrackStatus, make_tracker
from lookalike.geometry import xywh_to_xyxy
from lookalike.io import find_sequences, frames_from_table, read_mot
from lookalike.sim import BoxSceneConfig, simulate_boxes
from lookalike.trackers import Sort
from tests.sort_oracle import OracleSort


def _frame(k, xywh):
    return Frame(index=k, time=k / 25.0, detections=Detections(xywh=np.asarray(xywh, float).reshape(-1, 4)))


def _run_both(frames, **cfg):
    ours, oracle = Sort(Sort.Config(**cfg)), OracleSort(**cfg)
    for frame in frames:
        got = {t.track_id: t.xywh for t in ours.update(frame)}
        want = {tid: b for tid, b in oracle.update(xywh_to_xyxy(frame.detections.xywh))}
        assert got.keys() == want.keys(), f"frame {frame.index}"
        for tid in got:
            np.testing.assert_allclose(xywh_to_xyxy(got[tid]), want[tid], rtol=1e-7, atol=1e-6)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_identical_to_plain_oracle_on_simulated_scenes(seed):
    scene = simulate_boxes(BoxSceneConfig(seed=seed, frames=150, n_targets=8, false_positives_per_frame=1.0))
    _run_both(scene.frames)


def test_identical_to_plain_oracle_with_other_parameters():
    scene = simulate_boxes(BoxSceneConfig(seed=5, frames=120, miss_rate=0.3))
    _run_both(scene.frames, max_age=4, min_hits=2, iou_threshold=0.2)


def test_identical_to_oracle_on_real_detections(shared_data):
    seq = find_sequences(shared_data / "mot15" / "TUD-Campus")[0]
    frames = list(frames_from_table(read_mot(seq.det_path), seq.length, seq.frame_rate))
    _run_both(frames)


def test_empty_frames_are_harmless():
    tracker = make_tracker("sort")
    assert tracker.update(_frame(0, np.zeros((0, 4)))) == []
    out = tracker.update(_frame(1, [[10, 10, 20, 40]]))
    assert len(out) == 1  # first min_hits frames report new tracks at once
    for k in range(2, 6):
        assert tracker.update(_frame(k, np.zeros((0, 4)))) == []
    assert len(tracker._tracks) == 0  # deleted after max_age


def test_one_detection_becomes_a_confirmed_track():
    tracker = Sort()
    box = np.array([100.0, 50.0, 30.0, 60.0])
    statuses = []
    for k in range(8):
        out = tracker.update(_frame(k, box + [2 * k, 0, 0, 0]))
        assert len(out) == 1 and out[0].track_id == 1 and out[0].detection_index == 0
        statuses.append(out[0].status)
    assert statuses[-1] is TrackStatus.CONFIRMED
    np.testing.assert_allclose(out[0].xywh, box + [14, 0, 0, 0], atol=0.5)
    assert out[0].velocity[0] == pytest.approx(2.0 * 25.0, rel=0.1)  # pixels per second


def test_five_hundred_detections():
    rng = np.random.default_rng(0)
    grid = np.array([[x * 30.0, y * 30.0, 20.0, 20.0] for x in range(25) for y in range(20)])
    tracker = Sort()
    for k in range(5):
        out = tracker.update(_frame(k, grid + rng.normal(0, 0.5, grid.shape) * [1, 1, 0, 0]))
    assert len(out) == 500
    assert sorted(t.track_id for t in out) == list(range(1, 501))


def test_nan_input_is_rejected_before_the_tracker():
    with pytest.raises(ValueError, match="xywh: row 1"):
        _frame(0, [[0, 0, 1, 1], [np.nan, 0, 1, 1]])


def test_time_going_backwards_is_an_error():
    tracker = Sort()
    tracker.update(_frame(5, [[0, 0, 10, 10]]))
    with pytest.raises(ValueError, match="backwards"):
        tracker.update(_frame(4, [[0, 0, 10, 10]]))


def test_reset_restarts_ids():
    tracker = Sort()
    tracker.update(_frame(0, [[0, 0, 10, 10]]))
    tracker.reset()
    assert tracker.update(_frame(0, [[50, 50, 10, 10]]))[0].track_id == 1


def test_config_is_validated():
    with pytest.raises(ValueError, match="max_age"):
        Sort.Config(max_age=-1)
    with pytest.raises(ValueError, match="no parameter"):
        make_tracker("sort", max_agee=3)


@settings(max_examples=20, deadline=None)
@given(st.integers(0, 10_000))
def test_permuting_detections_does_not_change_tracks(seed):
    scene = simulate_boxes(BoxSceneConfig(seed=seed, frames=40, n_targets=5))
    rng = np.random.default_rng(seed)
    a, b = Sort(), Sort()
    for frame in scene.frames:
        perm = rng.permutation(len(frame.detections))
        shuffled = Frame(frame.index, frame.time, frame.detections.select(perm))
        ta = {t.track_id: t.xywh for t in a.update(frame)}
        tb = {t.track_id: t.xywh for t in b.update(shuffled)}
        # Ids may be born in another order; compare the sets of boxes.
        boxes_a = sorted(map(tuple, np.round(list(ta.values()), 6)))
        boxes_b = sorted(map(tuple, np.round(list(tb.values()), 6)))
        assert boxes_a == boxes_b


# Reference SORT (abewley/sort defaults) on ../shared/data/mot15, scored by TrackEval (MOT15, IoU 0.5).
REFERENCE = {
    "ADL-Rundle-6": (38.09, 75),
    "ETH-Bahnhof": (44.64, 71),
    "ETH-Sunnyday": (59.15, 22),
    "KITTI-13": (19.29, 16),
    "PETS09-S2L1": (61.86, 103),
    "TUD-Campus": (62.67, 6),
    "TUD-Stadtmitte": (71.71, 10),
}


@pytest.mark.parametrize("name", sorted(REFERENCE))
def test_mota_matches_reference_sort_on_mot15(shared_data, name):
    from lookalike.eval import evaluate_sequence
    from lookalike.io import MotTable, tracks_to_rows

    seq = find_sequences(shared_data / "mot15" / name)[0]
    tracker = Sort()
    rows = np.vstack(
        [tracks_to_rows(f.index, tracker.update(f))
         for f in frames_from_table(read_mot(seq.det_path), seq.length, seq.frame_rate)]
    )
    scores = evaluate_sequence(read_mot(seq.gt_path), MotTable.from_rows(rows), benchmark="MOT15",
                               num_frames=seq.length)
    mota, idsw = REFERENCE[name]
    assert 100 * scores["MOTA"] == pytest.approx(mota, abs=0.2)
    assert abs(scores["IDSW"] - idsw) <= 2


def _crowd(n_targets, frames, seed):
    side = int(64 * np.sqrt(n_targets))
    config = BoxSceneConfig(seed=seed, frames=frames, n_targets=n_targets, image_size=(side * 4 // 3, side),
                            false_positives_per_frame=0.05 * n_targets, speed_px=6.0)
    return simulate_boxes(config).frames


def test_sparse_matching_equals_plain_oracle_with_100_detections_a_frame(monkeypatch):
    import lookalike.trackers.parts.sort_tracks as core

    monkeypatch.setattr(core, "SPARSE_FROM", 1)  # the sparse path on every frame
    _run_both(_crowd(100, 25, seed=1))


def test_dense_matching_equals_plain_oracle_with_100_detections_a_frame():
    _run_both(_crowd(100, 25, seed=3))


def test_sparse_matching_equals_dense_with_1000_detections_a_frame(monkeypatch):
    import lookalike.trackers.parts.sort_tracks as core

    frames = _crowd(1000, 6, seed=2)
    a, b = Sort(), Sort()
    sparse = [a.update(f) for f in frames]
    monkeypatch.setattr(core, "SPARSE_FROM", 10**12)
    dense = [b.update(f) for f in frames]
    for s, d in zip(sparse, dense):
        assert np.array_equal(s.id, d.id) and np.array_equal(s.xywh, d.xywh)
        assert np.array_equal(s.detection_index, d.detection_index)
