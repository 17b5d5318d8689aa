"""The shared tracker parts: track table, lifecycle, association plan, state spaces, coasting and
score calibration."""

from __future__ import annotations

import math
import re

import numpy as np
import pytest

from lookalike.association.solver import assign
from lookalike.association.stages import Matching, Stage, cascade, run_plan, run_stage
from lookalike.motion.models import constant_velocity, kinematic_transition
from lookalike.motion.spaces import BoxCXCYWH, BoxXYAH, CentreCV, WorldCA, xyah_to_xywh, xywh_to_xyah
from lookalike.trackers.parts.coasting import Coasting
from lookalike.trackers.parts.lifecycle import Lifecycle
from lookalike.trackers.parts.self_calibration import ScoreCalibration
from lookalike.trackers.parts.table import TrackTable
from lookalike.trackers.parts.timing import FrameClock
from lookalike.types import Tracks, TrackStatus


def _table(n: int = 3) -> TrackTable:
    t = TrackTable(2, {"box": ((4,), float)})
    t.add(np.zeros((n, 2)), np.zeros((n, 2, 2)), hits=1, box=np.ones((n, 4)))
    return t


def test_table_assigns_ids_from_its_own_counter_and_keeps_columns_aligned() -> None:
    t = _table(3)
    assert list(t.ids) == [1, 2, 3] and t.hits.tolist() == [1, 1, 1] and t["box"].shape == (3, 4)
    t.keep(np.array([True, False, True]))
    rows = t.add(np.ones((2, 2)), np.zeros((2, 2, 2)))
    assert list(t.ids) == [1, 3, 4, 5] and rows.tolist() == [2, 3]
    assert t.hits.tolist() == [1, 1, 0, 0] and t["box"].shape == (4, 4) and len(t) == 4
    assert TrackTable(2).ids.tolist() == []  # another table counts on its own
    t.clear()
    assert len(t) == 0 and t.add(np.zeros((1, 2)), np.zeros((1, 2, 2))).tolist() == [0] and t.ids[0] == 1


def test_table_ages_and_records_misses_in_frames_and_seconds() -> None:
    t = _table(2)
    t.age()
    assert t.misses.tolist() == [1, 1]
    t.record(np.array([True, False]), 0.5)
    assert t.misses.tolist() == [0, 2] and t.unseen_s.tolist() == [0.0, 0.5]
    with pytest.raises(KeyError):
        t["nope"]
    with pytest.raises(KeyError):
        t.add(np.zeros((1, 2)), np.zeros((1, 2, 2)), nope=1)


def test_table_records_only_a_boolean_mask_of_hits() -> None:
    t = _table(3)
    det_of_track = np.array([-1, 0, 2])  # detection indices: -1 (missed) read as a hit, 0 as a miss
    with pytest.raises(ValueError, match=r"record: hit must be a boolean mask of shape \(3,\), got int64"):
        t.record(det_of_track, 0.1)
    with pytest.raises(ValueError, match="boolean mask of shape"):
        t.record(np.array([True, False]), 0.1)
    t.record(det_of_track >= 0, 0.1)
    assert t.misses.tolist() == [1, 0, 0]


def test_table_refuses_columns_of_another_length_and_stays_as_it_was() -> None:
    t = _table(2)
    for bad in ({"box": np.ones((1, 4))}, {"box": np.ones((3, 3))}, {"hits": np.ones(5)}):
        with pytest.raises(ValueError, match=f"column '{next(iter(bad))}'"):
            t.add(np.zeros((3, 2)), np.zeros((3, 2, 2)), **bad)
    with pytest.raises(ValueError, match="column 'cov'"):
        t.add(np.zeros((3, 2)), np.zeros((2, 2, 2)))
    assert {name: len(t[name]) for name in t.columns} == dict.fromkeys(t.columns, 2)
    assert t.add(np.zeros((1, 2)), np.zeros((1, 2, 2))).tolist() == [2] and t.ids.tolist() == [1, 2, 3]


def test_table_refuses_extra_columns_named_like_its_own_columns_or_methods() -> None:
    # a column 'age' replaced the age() method (then: 'numpy.ndarray' object is not callable); 'ids' changed its dtype
    for name in ("age", "keep", "ids", "mean", "_spec", "next_id"):
        with pytest.raises(ValueError, match=f"column name\\(s\\) \\['{name}'\\] are taken"):
            TrackTable(2, {name: ((), int)})
    assert TrackTable(2, {"age_s": ((), float)}).columns[-1] == "age_s"


def test_lifecycle_confirms_coasts_and_deletes() -> None:
    t = _table(3)
    t.hits[:] = [1, 3, 3]
    policy = Lifecycle(n_init=3, tentative_max_misses=1, max_misses=2)
    policy.confirm(t)
    assert t.confirmed.tolist() == [False, True, True]
    t.misses[:] = [1, 2, 3]
    assert policy.alive(t).tolist() == [False, True, False]
    assert policy.closed_set().alive(t).tolist() == [False, True, True]  # a closed set keeps confirmed tracks
    assert list(policy.status(t, np.arange(3))) == [TrackStatus.TENTATIVE, TrackStatus.LOST, TrackStatus.LOST]
    t.unseen_s[:] = [0.0, 0.4, 0.9]
    seconds = Lifecycle(n_init=3, tentative_max_misses=None, tentative_max_unseen_s=0.0, max_unseen_s=0.5)
    assert seconds.alive(t).tolist() == [True, True, False]
    assert seconds.alive(t, max_unseen_s=np.array([1.0, 0.1, 1.0])).tolist() == [True, False, True]
    assert Lifecycle(n_init=1).born_confirmed() and Lifecycle(n_init=3).born_confirmed(first_frame=True)
    with pytest.raises(ValueError):
        Lifecycle(n_init=0)
    # limits that would delete every track, even one matched this frame, were taken silently
    for bad in ({"tentative_max_misses": 0}, {"max_misses": -1}, {"max_unseen_s": float("nan")},
                {"tentative_max_unseen_s": -0.5}):
        with pytest.raises(ValueError, match=f"Lifecycle.{next(iter(bad))} must be >= "):
            Lifecycle(**bad)


def test_lifecycle_statuses_make_a_tracks_batch() -> None:
    t = _table(3)
    t.hits[:] = [1, 3, 3]
    t.misses[:] = [0, 0, 1]
    policy = Lifecycle(n_init=3)
    policy.confirm(t)
    status = policy.status(t, np.arange(3))
    tracks = Tracks(t.ids, status, xywh=t["box"])
    assert tracks.statuses() == [TrackStatus.TENTATIVE, TrackStatus.CONFIRMED, TrackStatus.LOST]
    assert tracks.status.tolist() == [0, 1, 2] and Tracks(t.ids, list(status)).status.tolist() == [0, 1, 2]
    with pytest.raises(ValueError, match="Tracks.status: give TrackStatus values"):
        Tracks(t.ids, np.array([TrackStatus.LOST, "lost", None], dtype=object))


def test_plan_runs_stages_in_order_on_what_is_left() -> None:
    cost = np.array([[0.1, 0.2, 0.9], [0.3, 0.1, 0.8]])
    fn = lambda r, c: cost[np.ix_(r, c)]  # noqa: E731
    first = Stage(np.array([False, True]), np.ones(3, dtype=bool), fn, name="second track only")
    second = Stage(np.array([True, True]), np.ones(3, dtype=bool), fn, max_cost=0.5)
    m = run_plan([first, second], 2, 3)
    assert m.det_of_track.tolist() == [0, 1] and m.free.tolist() == [False, False, True]
    assert m.stage_of_track.tolist() == [1, 0] and m.pairs.tolist() == [[0, 0], [1, 1]]
    # an index array keeps its order; stages never see matched tracks or taken detections
    seen: list[list[int]] = []
    probe = Stage(np.array([1, 0]), np.ones(3, dtype=bool), lambda r, c: (seen.append(list(r)), cost[np.ix_(r, c)])[1])
    run_plan([first, probe], 2, 3)
    assert seen == [[0]]
    assert run_plan([Stage(np.zeros(0, dtype=bool), np.ones(3, dtype=bool), fn)], 0, 3).det_of_track.tolist() == []


def test_plan_names_the_stage_whose_cost_mask_or_gate_does_not_fit() -> None:
    cost = np.array([[0.1, 0.9], [0.8, 0.2], [0.5, 0.5]])
    fn = lambda r, c: cost[np.ix_(r, c)]  # noqa: E731
    transposed = Stage(None, None, lambda r, c: fn(r, c).T, name="by IoU")
    with pytest.raises(ValueError, match=r"stage 0 \(by IoU\): its cost has shape \(2, 3\), expected \(3, 2\)"):
        run_plan([transposed], 3, 2)
    with pytest.raises(ValueError, match=r"stage 1: the tracks mask has shape \(2,\), expected \(3,\)"):
        run_plan([Stage(None, np.zeros(2, dtype=bool), fn), Stage(np.ones(2, dtype=bool), None, fn)], 3, 2)
    with pytest.raises(ValueError, match=r"the gate has shape \(2, 2\), expected \(3, 2\)"):
        run_stage(Stage(None, None, fn, gate=np.eye(2, dtype=bool)), Matching.empty(3, 2))
    gate = np.array([[True, False], [False, True], [False, False]])
    listed = run_plan([Stage([True, True, True], [True, True], fn, gate=gate)], 3, 2)  # lists work as arrays
    assert listed.det_of_track.tolist() == [0, 1, -1]


def test_plan_refuses_index_arrays_with_repeated_or_outside_indices() -> None:
    cost = np.array([[0.1, 0.2], [0.5, 0.5]])
    fn = lambda r, c: cost[np.ix_(r, c)]  # noqa: E731
    # a repeated detection was given to two tracks; -1 took the last track silently
    with pytest.raises(ValueError, match="detections indices must be distinct, from 0 to 1; got one twice"):
        run_plan([Stage(None, np.array([1, 1]), fn)], 2, 2)
    with pytest.raises(ValueError, match="tracks indices must be distinct, from 0 to 1; got -1"):
        run_plan([Stage(np.array([-1]), None, fn)], 2, 2)
    assert run_plan([Stage(np.array([1, 0]), np.array([], dtype=int), fn)], 2, 2).det_of_track.tolist() == [-1, -1]


def test_cascade_matches_recent_tracks_first() -> None:
    age = np.array([2, 1, 1])
    cost = np.array([[0.1], [0.2], [0.3]])
    stages = cascade(age, 5, np.ones(3, dtype=bool), np.ones(1, dtype=bool), lambda r, c: cost[np.ix_(r, c)], 0.5)
    assert [s.name for s in stages] == ["cascade level 1", "cascade level 2"]
    assert run_plan(stages, 3, 1).det_of_track.tolist() == [-1, 0, -1]
    assert assign(cost).matches.tolist() == [[0, 0]]  # one global assignment would pick the older track


def test_state_spaces_round_trip_boxes_and_share_the_transition() -> None:
    xywh = np.array([[10.0, 20.0, 30.0, 60.0]])
    np.testing.assert_allclose(xyah_to_xywh(xywh_to_xyah(xywh)), xywh)
    for space in (BoxCXCYWH(0.05, 0.01), BoxXYAH(0.05, 0.01, 0.01)):
        mean, cov = space.initial(space.measure(xywh))
        np.testing.assert_allclose(space.box(mean), xywh)
        m2, c2 = space.predict(mean.copy(), cov, 1.0)
        np.testing.assert_allclose(space.box(m2), xywh)  # no velocity yet: the box stays
        assert (np.linalg.eigvalsh(c2) > 0).all()
    centre = CentreCV(0.15, 0.05)
    mean, _ = centre.initial(centre.measure(xywh), xywh[:, 3])
    np.testing.assert_allclose(centre.box(mean, xywh), xywh)
    world = WorldCA(4.0, 0.05, 0.04, 0.5, 1.0)
    mean, cov = world.initial(np.array([[3.0, 4.0]]))
    assert cov[0, 0, 0] == pytest.approx((0.05 + 0.04 * 5) ** 2)
    F, _ = constant_velocity(4, 0.5)
    np.testing.assert_array_equal(kinematic_transition(4, 1, 0.5), F)


def test_state_spaces_refuse_noises_that_make_every_state_nan() -> None:
    cases = ((lambda: BoxCXCYWH(0.0, 0.01), "BoxCXCYWH.pos_noise must be a finite number > 0"),
             (lambda: BoxXYAH(0.05, math.nan, 0.01), "BoxXYAH.velocity_std_frac"),
             (lambda: CentreCV(0.1, -1.0), "CentreCV.accel_std_frac"),
             (lambda: WorldCA(4.0, -0.05, 0.0, 0.5, 1.0), "WorldCA.meas_std0_m must be a finite number >= 0"))
    for make, field in cases:
        with pytest.raises(ValueError, match=re.escape(field)):
            make()
    assert WorldCA(0.0, 0.0, 0.0, 0.0, 0.0).q_jerk == 0.0  # zeros are a world model's limits, not an error


def test_coasting_reports_only_misses_that_usually_end_in_a_return() -> None:
    coast = Coasting(coast_s=0.5, report_prob=0.6, min_count=2)
    assert coast.still(np.array([0.2, 0.5])).tolist() == [False, True]
    coast.observe(came_back=np.array([1, 1, 1]), died=np.array([3]))
    assert coast.decide(np.array([0, 1, 2, 3])).tolist() == [False, True, False, False]  # j=2: too few resolved
    assert not Coasting(0.5).decide(np.array([1])).any()  # reporting off


def test_score_calibration_lowers_thresholds_to_quantiles() -> None:
    cal = ScoreCalibration(0.9, 0.95, high_quantile=0.5, birth_quantile=0.5)
    assert cal.decide() == (0.9, 0.95, 0.9)  # nothing seen: the ceilings
    cal.observe_scores(np.linspace(0.2, 0.8, 101))
    high, birth, tentative = cal.decide()
    assert high == birth == pytest.approx(0.5, abs=0.01) and tentative == high
    plain = ScoreCalibration(0.9, 0.8)
    assert plain.decide() == (0.8, 0.8, 0.8)  # high never above birth


def test_costs_weigh_iou_by_score_and_gate_centre_distance_in_heights() -> None:
    from lookalike.association.costs import centre_distance_cost, iou_cost

    track = np.array([[0.0, 0.0, 10.0, 10.0]])
    dets = np.array([[0.0, 0.0, 10.0, 10.0], [5.0, 0.0, 10.0, 10.0], [50.0, 50.0, 10.0, 10.0]])
    plain = iou_cost(track, dets, min_iou=0.3)
    assert plain[0, 0] == 0.0 and plain[0, 1] == pytest.approx(1 - 1 / 3) and plain[0, 2] == np.inf
    weighed = iou_cost(track, dets, det_weight=np.array([0.5, 1.0, 1.0]))
    assert weighed[0, 0] == pytest.approx(0.5) and weighed[0, 2] == 1.0
    centre = np.array([[0.0, 0.0, 10.0, 20.0]])  # cx, cy, w, h
    cand = np.array([[0.0, 10.0, 10.0, 20.0], [0.0, 30.0, 10.0, 20.0], [0.0, 1.0, 40.0, 20.0]])
    cost = centre_distance_cost(centre, cand, np.array([[1.0]]), max_scale=1.5)
    assert cost[0, 0] == pytest.approx(0.5) and cost[0, 1] == np.inf  # 1.5 heights away: beyond the gate
    assert cost[0, 2] == np.inf  # four times as wide: not the same target


def test_boxtrack_config_names_the_bad_field() -> None:
    from lookalike.trackers.boxtrack_config import BoxTrackConfig

    for bad in ({"n_init": 0}, {"clutter_factor": 0}, {"low_score": 0.95}, {"reid_scale": 0.5},
                {"max_age_s": 0}):
        with pytest.raises(ValueError, match=next(iter(bad))):
            BoxTrackConfig(**bad)


def test_frame_clock_counts_regular_and_skipped_frames_and_ignores_frames_delivered_together() -> None:
    clock = FrameClock()
    assert [clock.steps(i / 30) for i in (1, 2, 3, 5, 6)] == pytest.approx([1, 1, 1, 2, 1])
    # A live camera delivering two frames 1 ms apart: the pair's step is a fraction of a frame, and the frames after
    # it still count as one step each (taking 1 ms as the interval made each count as 33).
    clock, t, steps = FrameClock(), 0.0, []
    for k in range(40):
        t += 0.001 if k == 20 else 1 / 30
        steps.append(clock.steps(t))
    assert steps[20] == pytest.approx(0.03)
    assert steps[21:] == pytest.approx([1.0] * 19)
    # The same when the pair comes first.
    clock = FrameClock()
    steps = [clock.steps(t) for t in (0.0, 0.001, *(0.001 + k / 30 for k in range(1, 10)))]
    assert steps[-5:] == pytest.approx([1.0] * 5)
