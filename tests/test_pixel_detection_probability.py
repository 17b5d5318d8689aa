"""The pixel pipeline's detection probability map (vision/detection_probability.py) and the bench's
per-set-up perception (bench/pixels.perception_pipeline)."""

import numpy as np
import pytest

from lookalike.bench.pixels import perception_pipeline
from lookalike.geometry.camera import Camera, Pose2D
from lookalike.sim.render_robots import RobotRenderer
from lookalike.vision.detection_probability import DetectionProbability, fit_quantile_map
from lookalike.vision.heading import HeadingClassifier
from lookalike.vision.hog_cascade import HogCascade
from lookalike.vision.pipeline import PipelineConfig, RobotPipeline, shipped_model_path
from tests.test_render_robots import random_walk_poses


def test_quantile_map_is_monotone_and_matches_the_target_distribution():
    rng = np.random.default_rng(0)
    margins, target = rng.normal(3.0, 2.0, 4000), rng.beta(6.0, 2.0, 4000)
    fitted = fit_quantile_map(margins, target, fitted_on={"seeds": [1]})
    p = fitted(np.sort(margins))
    assert (np.diff(p) >= 0).all() and p.min() >= 0 and p.max() <= 1
    assert abs(np.median(fitted(margins)) - np.median(target)) < 0.02
    assert fitted(np.array([-1e9, 1e9])).tolist() == [fitted.probability[0], fitted.probability[-1]]


def test_map_round_trips_and_bad_files_are_refused(tmp_path):
    fitted = fit_quantile_map(np.arange(10.0), np.linspace(0.2, 0.9, 10), knots=5, fitted_on={"seeds": [3]})
    path = tmp_path / "p.json"
    fitted.save(path)
    again = DetectionProbability.load(path)
    assert again == fitted and again.fitted_on == {"seeds": [3]}
    (tmp_path / "bad.json").write_text('{"margin": [1, 0], "probability": [0.1, 0.2]}')
    for bad in (tmp_path / "bad.json", tmp_path / "missing.json"):
        with pytest.raises(ValueError, match=bad.name):
            DetectionProbability.load(bad)


def test_map_changes_only_the_probability_not_the_detections():
    camera = Camera.default()
    det, head = HogCascade.load(shipped_model_path("detector")), HeadingClassifier.load(shipped_model_path("heading"))
    positions, headings = random_walk_poses(6, 3, seed=2, field_m=(3.4, 2.4), dt_s=0.1)
    renderer = RobotRenderer(camera=camera, seed=2)
    config = PipelineConfig(n_agents=3, max_detections=2)
    half = DetectionProbability((-100.0, 100.0), (0.5, 0.5))
    plain, mapped = RobotPipeline(det, head, camera, config), RobotPipeline(det, head, camera, config, half)
    seen = 0
    for k in range(6):
        image = renderer.render(positions[k], headings[k], Pose2D(-3.0, 0.0, 0.0)).image
        a, b = plain.perceive(image), mapped.perceive(image)
        np.testing.assert_array_equal(a.xywh, b.xywh)
        np.testing.assert_array_equal(a.heading, b.heading)
        assert (b.score == 0.5).all() and len(a) <= 2
        seen += len(a)
    assert seen > 0
    wide = perception_pipeline(mapped, n_agents=7, max_detections=10)
    assert wide.config.max_detections == 10 and wide.config.n_agents == 7 and wide.probability is half


def test_fit_command_refuses_an_unknown_preset(tmp_path, capsys):
    import importlib.util
    from pathlib import Path

    script = Path(__file__).resolve().parents[1] / "research" / "pixel_probability" / "fit.py"
    spec = importlib.util.spec_from_file_location("pixel_probability_fit", script)
    assert spec is not None and spec.loader is not None
    fit = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(fit)
    main = fit.main
    assert main(["-o", str(tmp_path / "p.json"), "--pixel-setups", "nope"]) == 2
    assert "nope" in capsys.readouterr().err and not (tmp_path / "p.json").exists()
