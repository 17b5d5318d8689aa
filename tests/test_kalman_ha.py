"""Kalman-HA, Kalman-HA2 and the JPDA tracker: filtering, lifecycle, identification, robustness."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from lookalike.sim import preset, simulate_robots
from lookalike.trackers import make_tracker, tracker_names
from lookalike.trackers.parts.identity import labels_from_tracks
from lookalike.types import Beacons, Detections, Frame, TrackStatus

TRACKERS = ("kalman_ha", "kalman_ha2", "jpda")


def _single_target_frames(n: int = 60, seed: int = 0) -> list[Frame]:
    rng = np.random.default_rng(seed)
    t = np.arange(n) / 30.0
    path = np.stack([2.0 + 0.3 * t + 0.1 * t**2, 0.5 * np.sin(t)], 1) + rng.normal(0, 0.05, (n, 2))
    return [Frame(index=k, time=float(t[k]), detections=Detections(position=path[k:k + 1], heading=np.array([0.3]),
                  score=np.array([0.9]))) for k in range(n)]


def test_registered():
    assert set(TRACKERS) <= set(tracker_names())


def test_jpda_equals_kalman_ha_for_one_target_without_clutter():
    ha = make_tracker("kalman_ha", n_agents=1)
    jpda = make_tracker("jpda", n_agents=1, clutter_density=1e-12, p_detection=0.9)
    for frame in _single_target_frames():
        a, b = ha.update(frame), jpda.update(frame)
        assert len(a) == len(b) == 1
        np.testing.assert_allclose(a[0].position, b[0].position, atol=1e-8)
        np.testing.assert_allclose(a[0].velocity, b[0].velocity, atol=1e-8)
        assert b[0].detection_index == 0


def test_kalman_ha_tracks_end_at_first_miss():
    tracker = make_tracker("kalman_ha", n_agents=1)
    frames = _single_target_frames(10)
    ids = {tracker.update(f)[0].track_id for f in frames[:5]}
    assert tracker.update(Frame(index=5, time=frames[5].time)) == []
    ids |= {tracker.update(f)[0].track_id for f in frames[6:]}
    assert ids == {1, 2}


def test_kalman_ha2_confirms_and_coasts():
    tracker = make_tracker("kalman_ha2", n_agents=1)
    frames = _single_target_frames(40)
    status = [tracker.update(f)[0].status for f in frames[:5]]
    assert status[0] is TrackStatus.TENTATIVE and status[-1] is TrackStatus.CONFIRMED
    # Ten missed frames (0.33 s): the confirmed track coasts and then takes the robot back.
    for k in range(5, 15):
        out = tracker.update(Frame(index=k, time=frames[k].time))
        assert [t.status for t in out] == [TrackStatus.LOST]
    out = tracker.update(frames[15])
    assert [(t.track_id, t.detection_index) for t in out] == [(1, 0)]


def test_kalman_ha2_ignores_low_score_births():
    tracker = make_tracker("kalman_ha2", n_agents=1)
    frame = Frame(index=0, time=0.0, detections=Detections(position=[[2.0, 0.0]], heading=[0.0], score=[0.1]))
    assert tracker.update(frame) == []


def test_identification_follows_the_reports():
    """Two robots with distinct reported headings: each detection gets its robot's id."""
    frames = []
    for k in range(90):
        t = k / 30.0
        det = Detections(position=[[2.0, 1.0], [3.0, -1.0]], heading=[1.0 + 0.2 * t, -2.0],
                         score=[0.9, 0.9])
        beacons = Beacons(agent_id=[0, 1], t_sent=[t - 0.05, t - 0.05], t_received=[t, t],
                          heading=[-2.0, 1.0 + 0.2 * (t - 0.05)]) if k % 3 == 0 else Beacons.empty()
        frames.append(Frame(index=k, time=t, detections=det, beacons=beacons))
    for name in TRACKERS:
        tracker = make_tracker(name, n_agents=2)
        labels = [labels_from_tracks(2, tracker.update(f)) for f in frames]
        assert all((lab == [1, 0]).all() for lab in labels[10:]), name


@pytest.mark.parametrize("name", TRACKERS)
def test_robustness(name):
    cfg = preset("m5n3")
    seq = simulate_robots(cfg, 600, seed=77)
    frames = list(seq.frames())
    # (1) all reports of robot 0 lost for 5 s; (2) reports arrive out of order; (3) 100 empty frames.
    out_frames = []
    for f in frames:
        b = f.beacons
        keep = ~((b.agent_id == 0) & (b.t_sent >= 5.0) & (b.t_sent < 10.0))
        b = Beacons(agent_id=b.agent_id[keep][::-1], t_sent=b.t_sent[keep][::-1],
                    t_received=b.t_received[keep][::-1], heading=b.heading[keep][::-1])
        det = Detections.empty() if 300 <= f.index < 400 else f.detections
        out_frames.append(dataclasses.replace(f, beacons=b, detections=det))
    late = Beacons(agent_id=[1], t_sent=[0.5], t_received=[12.0], heading=[0.0])  # a very late report
    out_frames[360] = dataclasses.replace(out_frames[360], beacons=late)
    tracker = make_tracker(name, n_agents=3)
    labels = []
    for f in out_frames:
        tracks = tracker.update(f)
        lab = labels_from_tracks(len(f.detections), tracks)
        assert ((lab >= -1) & (lab < 3)).all()
        assert len(set(lab[lab >= 0])) == (lab >= 0).sum()  # an agent labels at most one detection
        for t in tracks:
            assert np.isfinite(t.position).all()
        labels.append(lab)
    assert all(len(lab) == 0 for lab in labels[300:400])
    truth = seq.true_labels()
    tail = np.concatenate(labels[450:])
    assert np.mean(tail == np.concatenate(truth[450:])) > 0.5  # recovers after the gap


def test_bad_input():
    with pytest.raises(ValueError, match="confirm_hits"):
        make_tracker("kalman_ha2", confirm_hits=6, confirm_window=5)
    with pytest.raises(ValueError, match="p_detection"):
        make_tracker("jpda", p_detection=0.0)
    tracker = make_tracker("kalman_ha")
    with pytest.raises(ValueError, match="position"):
        tracker.update(Frame(index=0, time=0.0, detections=Detections(xywh=[[0, 0, 1, 1]])))
    tracker.update(Frame(index=0, time=1.0))
    with pytest.raises(ValueError, match="backwards"):
        tracker.update(Frame(index=1, time=0.5))
