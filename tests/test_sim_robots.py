"""Robot-world simulator: statistics match the configuration, occlusion, determinism, validation."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from lookalike.geometry import angle_diff
from lookalike.sim import (
    NetworkConfig,
    ObserverConfig,
    RobotWorldConfig,
    SensorConfig,
    preset,
    simulate_arrays,
    simulate_robots,
)
from lookalike.sim.robots_sensors import detection_probability, occlusion_fraction


@pytest.fixture(scope="module")
def long_run():
    cfg = dataclasses.replace(preset("m10n7"), max_detections=40)  # never truncate: raw statistics
    return cfg, simulate_arrays(cfg, 20000, seed=11)


def _expected_heading_error(sensor: SensorConfig) -> float:
    """Mean absolute error of the heading model by numerical integration (independent of the code)."""
    width = 2 * math.pi / sensor.heading_classes
    theta = np.linspace(-math.pi, math.pi, 721)[:-1]
    eps = np.linspace(-5, 5, 801) * sensor.heading_noise_rad
    weight = np.exp(-0.5 * (eps / sensor.heading_noise_rad) ** 2)
    weight /= weight.sum()
    total = 0.0
    for flip, p in ((0.0, 1 - sensor.heading_flip_prob), (math.pi, sensor.heading_flip_prob)):
        est = np.round((theta[:, None] + flip + eps[None]) / width) * width
        err = np.abs(np.angle(np.exp(1j * (est - theta[:, None]))))
        total += p * float((err * weight[None]).sum(axis=1).mean())
    return total


def test_heading_error_matches_model_and_paper(long_run):
    cfg, a = long_run
    tp = a.det_valid & (a.det_label >= 0)
    t, _ = np.nonzero(tp)
    err = np.abs(angle_diff(a.det_heading[tp], a.true_heading[t, a.det_label[tp]]))
    assert abs(err.mean() - _expected_heading_error(cfg.sensor)) < math.radians(1.0)
    assert 14 < math.degrees(err.mean()) < 20  # seed A: about 17 degrees
    assert abs((err > math.pi / 2).mean() - cfg.sensor.heading_flip_prob) < 0.01


def test_miss_rate_matches_detection_probability(long_run):
    cfg, a = long_run
    d = np.hypot(a.true_position[..., 0], a.true_position[..., 1])
    p = detection_probability(d, a.occlusion, cfg.sensor, cfg.observer)[a.visible]
    measured = a.n_misses.sum() / a.visible.sum()
    assert abs(measured - (1 - p.mean())) < 0.01
    detected = np.zeros(a.visible.shape, dtype=bool)
    t, s = np.nonzero(a.det_valid & (a.det_label >= 0))
    detected[t, a.det_label[t, s]] = True
    assert not (detected & ~a.visible).any()  # nothing out of view is detected


def test_false_positive_rate_and_scores(long_run):
    cfg, a = long_run
    fp = a.det_valid & (a.det_label < 0)
    assert abs(fp.sum(axis=1).mean() - cfg.sensor.fp_per_frame) < 0.05
    ta, tb = cfg.sensor.fp_score_beta
    assert abs(a.det_score[fp].mean() - ta / (ta + tb)) < 0.02
    assert a.det_score[a.det_valid & (a.det_label >= 0)].mean() > a.det_score[fp].mean() + 0.2


def test_report_loss_rate_and_timing(long_run):
    cfg, a = long_run
    r = a.reports
    loss = 1 - len(r.agent_id) / r.n_sent
    assert abs(loss - cfg.network.expected_loss()) < 0.02
    assert (r.t_received >= r.t_sent + cfg.network.delay_s - 1e-12).all()
    assert np.all(np.diff(r.t_received) >= 0)
    # Each frame carries exactly the reports received since the previous frame.
    k = np.searchsorted(a.time, r.t_received - 1e-9)
    assert np.array_equal(np.bincount(k, minlength=len(a)), np.diff(r.frame_offsets))


def test_report_rate_and_bursts():
    net = NetworkConfig(rate_hz=5.0, loss_prob=0.0, burst_rate_hz=0.2, burst_s=2.0, jitter_s=0.3)
    cfg = RobotWorldConfig(n_agents=3, network=net)
    a = simulate_arrays(cfg, 30 * 600, seed=3)
    assert abs(a.reports.n_sent / (3 * 600) - 5.0) < 0.05
    assert abs(1 - len(a.reports.agent_id) / a.reports.n_sent - net.expected_loss()) < 0.05
    assert (np.diff(a.reports.t_sent) < 0).any()  # jitter reorders reports


def test_occlusion_hides_the_farther_robot():
    near, far = np.array([1.5, 0.0]), np.array([3.0, 0.05])
    occ = occlusion_fraction(np.stack([near, far])[None], 0.2)[0]
    assert occ[0] == 0 and occ[1] > 0.8
    sensor, observer = SensorConfig(), ObserverConfig()
    p = detection_probability(np.array([1.5, 3.0]), occ, sensor, observer)
    assert p[0] > 0.9 and p[1] == 0
    beside = occlusion_fraction(np.array([[[1.5, 0.0], [3.0, 1.5]]]), 0.2)[0]
    assert (beside == 0).all()


def test_fully_occluded_robots_are_never_detected(long_run):
    cfg, a = long_run
    hidden = a.visible & (a.occlusion >= cfg.sensor.occlusion_hide)
    assert hidden.sum() > 100
    t, s = np.nonzero(a.det_valid & (a.det_label >= 0))
    assert not hidden[t, a.det_label[t, s]].any()


def test_robots_leave_and_reenter_the_view():
    a = simulate_arrays(preset("m5n3"), 3000, seed=5)
    changes = np.abs(np.diff(a.visible.astype(int), axis=0)).sum(axis=0)
    assert (changes >= 2).all()
    speed = np.linalg.norm(np.diff(a.field_position, axis=0), axis=2) * 30
    assert speed.max() <= preset("m5n3").motion.max_speed_mps * 1.01


def test_frames_in_view_and_a_warning_for_a_robot_never_in_view():
    """Counted from ``visible``; a robot pushed out of the field of view by a narrow one gets a warning line."""
    cfg = preset("m3n2")
    seq = simulate_robots(cfg, 60, seed=1)
    counts = seq.frames_in_view()
    assert counts.tolist() == seq.arrays.visible.sum(axis=0).tolist()
    lines = seq.view_summary()
    assert lines[0] == f"frames with each robot in view (of 60): robot 1: {counts[0]}, robot 2: {counts[1]}"
    warned = [int(line.split()[2]) - 1 for line in lines[1:]]
    assert warned == [i for i in range(2) if counts[i] == 0]
    assert all(line.startswith("warning: robot ") and "never in view" in line for line in lines[1:])
    narrow = dataclasses.replace(cfg, observer=dataclasses.replace(cfg.observer, max_range_m=0.31))
    blind = simulate_robots(narrow, 30, seed=1)
    assert blind.frames_in_view().tolist() == [0, 0]
    assert [line.split(" (")[0] for line in blind.view_summary()[1:]] == [
        "warning: robot 1 is never in view", "warning: robot 2 is never in view"]


def test_identical_seeds_identical_sequences():
    cfg = preset("m3n2")
    a, b, c = simulate_arrays(cfg, 500, 7), simulate_arrays(cfg, 500, 7), simulate_arrays(cfg, 500, 8)
    for f in ("det_position", "det_heading", "det_score", "det_label", "true_position"):
        assert np.array_equal(getattr(a, f), getattr(b, f))
    assert np.array_equal(a.reports.t_received, b.reports.t_received)
    assert not np.array_equal(a.det_position, c.det_position)


def test_frames_and_truth():
    cfg = preset("m5n3")
    seq = simulate_robots(cfg, 200, seed=2)
    frames = list(seq.frames())
    assert len(frames) == 200
    assert all(len(f.detections) <= 5 for f in frames)
    assert sum(len(f.beacons) for f in frames) == len(seq.arrays.reports.agent_id)
    labels = seq.true_labels()
    assert all(np.array_equal(f.detections.label, lab) for f, lab in zip(frames, labels))
    assert frames[10].time == pytest.approx(10 / 30)
    assert np.isnan(seq.true_positions_visible()[~seq.arrays.visible]).all()


def test_bad_input_raises():
    with pytest.raises(ValueError, match="n_frames"):
        simulate_arrays(preset("m3n2"), 0, 1)
    with pytest.raises(ValueError, match="unknown team"):
        preset("m4x4")
    with pytest.raises(ValueError, match="1..1000"):
        preset("m0n4")
    assert (preset("m7n4").max_detections, preset("n4m7").n_agents) == (7, 4)
    with pytest.raises(ValueError, match="loss_prob"):
        NetworkConfig(loss_prob=1.5)
    with pytest.raises(ValueError, match="p_walk"):
        RobotWorldConfig.from_dict({"motion": {"p_walk": 0.9}})
    cfg = preset("m10n7")
    assert RobotWorldConfig.from_dict(cfg.to_dict()) == cfg
