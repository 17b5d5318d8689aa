"""The pixels → identities pipeline (vision/pipeline.py), `track --pipeline robots` and `bench pixels`."""

import json

import numpy as np
import pytest
from typer.testing import CliRunner

from lookalike.bench.pixels import match_truth
from lookalike.cli import app
from lookalike.eval import identification_success_rate
from lookalike.geometry.camera import Camera, Pose2D
from lookalike.io.results import validate
from lookalike.io.video_frames import video_info
from lookalike.sim.render_robots import ROBOT_HEIGHT_M, ROBOT_WIDTH_M, RobotRenderer
from lookalike.types import Beacons, Detections
from lookalike.vision.heading import HeadingClassifier
from lookalike.vision.hog_cascade import HogCascade
from lookalike.vision.pipeline import PipelineConfig, RobotPipeline, check_image, labelled_rows, shipped_model_path
from tests.test_render_robots import random_walk_poses

runner = CliRunner()
N_ROBOTS, FRAMES, DT = 2, 40, 0.1


@pytest.fixture(scope="module")
def models():
    """The shipped detector and heading classifier, and their paths."""
    det_path, head_path = shipped_model_path("detector"), shipped_model_path("heading")
    return HogCascade.load(det_path), HeadingClassifier.load(head_path), det_path, head_path


@pytest.fixture(scope="module")
def scene():
    """Two robots walking 1.3-4.7 m in front of a fixed camera; every robot reports its heading each frame."""
    camera = Camera.default()
    positions, headings = random_walk_poses(FRAMES, N_ROBOTS, seed=5, field_m=(3.4, 2.4), dt_s=DT)
    renderer = RobotRenderer(camera=camera, seed=5)
    observer = Pose2D(-3.0, 0.0, 0.0)
    frames = [renderer.render(positions[k], headings[k], observer) for k in range(FRAMES)]
    beacons = [Beacons(agent_id=np.arange(N_ROBOTS), t_sent=np.full(N_ROBOTS, k * DT),
                       t_received=np.full(N_ROBOTS, k * DT), heading=headings[k]) for k in range(FRAMES)]
    return camera, frames, beacons


@pytest.mark.parametrize("identifier", ["kalman_ha", "lstm"])
def test_pipeline_identifies_rendered_robots_better_than_chance(models, scene, identifier):
    det, head, _, _ = models
    camera, frames, beacons = scene
    pipe = RobotPipeline(det, head, camera, PipelineConfig(identifier=identifier, n_agents=N_ROBOTS, max_detections=3))
    predicted, truth, position_errors = [], [], []
    for k, (rendered, reports) in enumerate(zip(frames, beacons)):
        res = pipe.update(rendered.image, reports, k * DT)
        n = len(res.detections)
        assert n <= 3
        assert res.labels.shape == (n,) and res.labels.dtype.kind == "i"
        assert ((res.labels >= -1) & (res.labels < N_ROBOTS)).all()
        assert res.detections.position.shape == (n, 2) and np.isfinite(res.detections.position).all()
        assert (np.abs(res.detections.heading) <= np.pi).all() and res.detections.heading_std.shape == (n,)
        true = match_truth(res.detections.xywh, rendered.xywh, rendered.robot_id, 0.3)
        for i in np.flatnonzero(true >= 0):
            j = int(np.flatnonzero(rendered.robot_id == true[i])[0])
            position_errors.append(np.hypot(*(res.detections.position[i] - rendered.position_m[j])))
        predicted.append(res.labels)
        truth.append(true)
    assert sum(len(t) for t in truth) >= FRAMES  # the robots are found
    assert np.median(position_errors) < 0.4  # metres: boxes land near the robots' feet
    # Chance is 1/(N+1) = 0.33 for labels among {false positive, robot 0, robot 1}.
    assert identification_success_rate(predicted, truth) > 0.7


def test_bad_images_are_refused_clearly(models):
    det, head, _, _ = models
    pipe = RobotPipeline(det, head)
    good = np.zeros((480, 640, 3), np.uint8)
    for bad, words in [
        (np.zeros((0, 640, 3), np.uint8), "empty"),
        (good.astype(np.float32), "dtype"),
        (np.zeros((480, 640, 2), np.uint8), "shape"),
        (np.zeros((240, 320, 3), np.uint8), "calibrated"),
        (good.tolist(), "numpy array"),
    ]:
        with pytest.raises(ValueError, match=words):
            pipe.perceive(bad)
    assert isinstance(pipe.perceive(good[:, :, 0]), Detections)  # grey is fine
    with pytest.raises(ValueError, match="observer_yaw_rad"):
        pipe.perceive(good, observer_yaw_rad=float("nan"))
    assert check_image(good[:, :, :1]).shape == (480, 640, 3)


def test_bad_configuration_is_refused(models):
    det, head, _, _ = models
    with pytest.raises(ValueError, match="identifier"):
        RobotPipeline(det, head, config=PipelineConfig(identifier="no-such-tracker"))
    with pytest.raises(ValueError, match="n_agents"):
        PipelineConfig(n_agents=0)
    with pytest.raises(ValueError, match="detect_scale"):
        PipelineConfig(detect_scale=0.0)
    with pytest.raises(ValueError, match="kind"):
        shipped_model_path("tracker")
    with pytest.raises(ValueError, match="no parameter"):
        RobotPipeline(det, head, config=PipelineConfig(identifier="lstm", identifier_params=(("fov_deg", 70.0),)))
    for bad, name in [({"field_m": (9.0, 0.0)}, "field_m"), ({"max_range_m": -1.0}, "max_range_m"),
                      ({"field_margin_m": -0.1}, "field_margin_m"), ({"size_tolerance": 0.5}, "size_tolerance")]:
        with pytest.raises(ValueError, match=name):
            PipelineConfig(**bad)


def test_implausible_detections_are_dropped_and_counted(models):
    """Outside the field (given the observer's field pose), beyond the range, or a box of the wrong size for its
    ground position: dropped, each counted once under its first reason; the rest kept."""
    det, head, _, _ = models
    camera = Camera.default()
    config = PipelineConfig(field_m=(9.0, 6.0), field_margin_m=0.5, max_range_m=7.0, size_tolerance=2.0)
    pipe = RobotPipeline(det, head, camera, config)
    # Observer at field (-4.3, 0) looking along +x turned 0.3 rad left: ego (2, 0) is in the field; ego (5, 2.5)
    # is at field y ≈ 3.9 (outside 3 + 0.5); ego (7.5, 0) is beyond 7 m but inside the field.
    ego = np.array([[2.0, 0.0], [5.0, 2.5], [7.5, 0.0], [3.0, -0.5], [1.2, 0.3]])
    boxes = camera.ground_to_box(ego, ROBOT_HEIGHT_M, ROBOT_WIDTH_M)
    boxes[3, 1] += 0.75 * boxes[3, 3]
    boxes[3, 3] *= 0.25  # a quarter of the height a robot 3 m away has, same foot point
    ok = pipe.plausible(boxes, ego, 0.3, (-4.3, 0.0))
    assert ok.tolist() == [True, False, False, False, True]
    assert pipe.dropped == {"outside field": 1, "beyond range": 1, "size": 1}
    # Without the observer's field position the field is not checked; without settings nothing is.
    assert pipe.plausible(boxes, ego, 0.3).tolist() == [True, True, False, False, True]
    assert RobotPipeline(det, head, camera).plausible(boxes, ego, 0.3, (-4.3, 0.0)).all()
    pipe.reset()
    assert sum(pipe.dropped.values()) == 0


def test_ground_position_of_a_box_cut_by_the_image_bottom(models):
    det, head, _, _ = models
    camera = Camera.default()
    pipe = RobotPipeline(det, head, camera)
    truth = np.array([[0.45, 0.05], [2.0, -0.3]])
    boxes = camera.ground_to_box(truth, ROBOT_HEIGHT_M, ROBOT_WIDTH_M)
    assert boxes[0, 1] + boxes[0, 3] > 480  # the near robot's feet are below the image
    clipped = boxes.copy()
    clipped[:, 3] = np.minimum(clipped[:, 1] + clipped[:, 3], 480) - clipped[:, 1]
    got = pipe.ground_positions(clipped)
    np.testing.assert_allclose(got, truth, atol=0.02)
    assert np.linalg.norm(camera.box_to_ground(clipped[:1])[0] - truth[0]) > 0.1  # the naive foot point is off


def test_labelled_rows_keep_identified_detections_only():
    det = Detections(xywh=[[1, 2, 3, 4], [5, 6, 7, 8]], position=[[1.0, 0.5], [2.0, -1.0]])
    rows = labelled_rows(4, det, np.array([-1, 1]), [])
    np.testing.assert_allclose(rows, [[5, 2, 5, 6, 7, 8, 1.0, 2.0, -1.0, -1.0]])


def test_track_pipeline_robots_end_to_end(tmp_path):
    res = runner.invoke(app, ["simulate", "--preset", "m3n2", "--frames", "12", "--seed", "3", "-o", str(tmp_path)])
    assert res.exit_code == 0, res.output
    assert "frames with each robot in view (of 12): robot 1: " in res.output
    seq = tmp_path / "m3n2-000003.jsonl"
    clip = tmp_path / "clip.mp4"
    res = runner.invoke(app, ["render-robots", str(seq), "-o", str(clip)])
    assert res.exit_code == 0, res.output
    assert video_info(clip)[2] == (640, 480)
    tracks, annotated = tmp_path / "tracks.txt", tmp_path / "annotated.mp4"
    args = ["track", "--video", str(clip), "--pipeline", "robots", "--reports", str(seq), "-t", "kalman_ha",
            "-o", str(tracks), "--annotate", str(annotated)]  # the shipped models
    res = runner.invoke(app, args)
    assert res.exit_code == 0, res.output
    assert "12 frames" in res.output
    assert video_info(annotated)[0] == 12
    text = tracks.read_text().strip()
    for line in text.splitlines() if text else []:
        cols = line.split(",")
        assert len(cols) == 10 and 1 <= int(cols[0]) <= 12 and 1 <= int(cols[1]) <= 2
    res = runner.invoke(app, [a for a in args if a not in ("--reports", str(seq))])
    assert res.exit_code != 0 and "--reports" in res.output
    res = runner.invoke(app, [("boxtrack" if a == "kalman_ha" else a) for a in args])  # (sort, the default: set)
    assert res.exit_code != 0 and "identifier" in res.output
    res = runner.invoke(app, args + ["--detector-model", str(seq)])
    assert res.exit_code != 0 and "HOG cascade" in res.output
    res = runner.invoke(app, args + ["--detector", "blob"])
    assert res.exit_code != 0 and "--pipeline" in res.output


def test_bench_pixels_tiny(models, tmp_path):
    _, _, det_path, head_path = models
    out = tmp_path / "rows.json"
    res = runner.invoke(app, ["bench", "pixels", "--setups", "m3n2", "--identifiers", "kalman_ha2,lstm",
                              "--sequences", "1", "--frames", "10", "--detector-model", str(det_path),
                              "--heading-model", str(head_path), "--json", str(out)])
    assert res.exit_code == 0, res.output
    doc = json.loads(out.read_text())
    validate(doc)  # the results schema
    rows = [r["metrics"] | {"tracker": r["tracker"]} for r in doc["tables"]["identification"]]
    assert [r["tracker"] for r in rows] == ["kalman_ha2", "lstm"]
    for r in rows:
        assert 0 <= r["success_rate_pixels"] <= 1 and 0 <= r["success_rate_simulated"] <= 1
        assert r["gap"] == pytest.approx(r["success_rate_pixels"] - r["success_rate_simulated"], abs=2e-4)
    assert "Perception" in res.output
    res = runner.invoke(app, ["bench", "pixels", "--setups", "m9x9"])
    assert res.exit_code != 0 and "m9x9" in res.output


def test_bench_pixels_weights_replace_the_lstms_on_both_sides(models, tmp_path):
    from lookalike.trackers.lstm.weights import shipped_weights_path

    _, _, det_path, head_path = models
    base = ["bench", "pixels", "--setups", "m3n2", "--identifiers", "lstm", "--sequences", "1", "--frames", "10",
            "--detector-model", str(det_path), "--heading-model", str(head_path)]
    docs = []
    for extra in ([], ["--weights", str(shipped_weights_path(2, 3))]):
        out = tmp_path / f"rows{len(extra)}.json"
        res = runner.invoke(app, base + extra + ["--json", str(out)])
        assert res.exit_code == 0, res.output
        docs.append(json.loads(out.read_text()))
    same = [d["tables"]["identification"][0]["metrics"] for d in docs]
    for key in ("success_rate_pixels", "success_rate_simulated"):
        assert same[0][key] == same[1][key]  # the shipped weights by path: the same labels
    assert docs[1]["header"]["options"]["weights"] == str(shipped_weights_path(2, 3))
    res = runner.invoke(app, base + ["--weights", str(shipped_weights_path(7, 10))])  # weights for another team
    assert res.exit_code != 0 and "lstm_m10_n7" in res.output
    res = runner.invoke(app, base[:3] + ["m3n2,m5n3"] + base[4:] + ["--weights", str(shipped_weights_path(2, 3))])
    assert res.exit_code != 0 and "one set-up" in res.output
