"""The detector measured on recordings (learn.recording_sensor): simulated truth in, its parameters back out."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from lookalike.learn.recording_sensor import fit_sensor
from lookalike.sim import preset, simulate_arrays


def _world(**sensor):
    cfg = preset("m5n3")
    return dataclasses.replace(cfg, sensor=dataclasses.replace(cfg.sensor, heading_classes=0, **sensor))


def test_recovers_the_simulators_detector() -> None:
    cfg = _world(fp_per_frame=0.8, heading_flip_prob=0.1, heading_noise_rad=math.radians(10), p_detect=0.8,
                 std_x0_m=0.1, std_x_per_m=0.05)
    arrays = [simulate_arrays(cfg, 1500, seed) for seed in range(2)]
    fit = fit_sensor(arrays, dataclasses.replace(cfg.sensor, fp_per_frame=3.0, p_detect=0.3), cfg.observer)
    kept_fp = sum(int(((a.det_label < 0) & a.det_valid).sum()) for a in arrays) / 3000
    assert fit.fp_per_frame == pytest.approx(kept_fp)
    assert fit.fp_per_frame == pytest.approx(0.8, abs=0.15)
    assert fit.p_detect == pytest.approx(0.8, abs=0.05)
    assert fit.heading_flip_prob == pytest.approx(0.1, abs=0.03)
    assert math.degrees(fit.heading_noise_rad) == pytest.approx(10, abs=2.5)
    assert fit.std_x0_m + 4 * fit.std_x_per_m == pytest.approx(0.1 + 4 * 0.05, rel=0.25)
    assert fit.heading_classes == 0
    tp_mean = fit.tp_score_beta[0] / sum(fit.tp_score_beta)
    assert tp_mean == pytest.approx(6 / 8, abs=0.05)  # the preset's Beta(6, 2), lowered by occlusion


def test_saturated_scores_give_a_concentrated_beta() -> None:
    cfg = _world()
    a = simulate_arrays(cfg, 300, 3)
    a = dataclasses.replace(a, det_score=np.where(a.det_valid, 1.0, 0.0))
    fit = fit_sensor([a], cfg.sensor, cfg.observer)
    alpha, beta = fit.tp_score_beta
    assert alpha / (alpha + beta) > 0.99 and alpha + beta >= 100


def test_no_robot_detection_is_refused() -> None:
    cfg = _world()
    a = simulate_arrays(cfg, 50, 1)
    a = dataclasses.replace(a, det_valid=np.zeros_like(a.det_valid))
    with pytest.raises(ValueError, match="no detection"):
        fit_sensor([a], cfg.sensor, cfg.observer)


def test_recordings_without_truth_are_refused() -> None:
    cfg = _world()
    a = simulate_arrays(cfg, 50, 1)
    a = dataclasses.replace(a, visible=np.zeros_like(a.visible))
    with pytest.raises(ValueError, match="no usable truth"):
        fit_sensor([a], cfg.sensor, cfg.observer)
