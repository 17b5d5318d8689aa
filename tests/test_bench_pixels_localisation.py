"""``bench pixels`` reports seed A's Table II (localisation error) from pixels beside the simulator's."""

from __future__ import annotations

import math

from lookalike.bench.pixels import PIXEL_COLUMNS, PIXEL_KEYS, pixels_results, pixels_table
from lookalike.sim.robot_camera import pixel_camera
from lookalike.vision.pipeline import PipelineConfig, RobotPipeline


def test_localisation_error_columns_from_pixels_and_simulated():
    camera = pixel_camera()
    pipe = RobotPipeline.from_files(None, None, camera, PipelineConfig())
    # seed 700003: both robots in the camera's view in all 12 frames
    rows, perception = pixels_table(["m3n2"], ["jpda"], 1, 12, 700_003, pipe, camera, 0.3)
    (row,) = rows
    assert list(row) == list(PIXEL_COLUMNS)
    for key in ("Pixels loc. (m)", "Simulated loc. (m)"):
        assert math.isnan(row[key]) or 0 <= row[key] < 10
    assert row["Simulated loc. (m)"] >= 0  # the simulator's detections of visible robots give positions
    for key in ("Pixels robots (%)", "Sim robots (%)"):  # true robots only: like for like
        assert math.isnan(row[key]) or 0 <= row[key] <= 100
    doc = pixels_results(rows, perception, ["m3n2"], 1, 12)
    metrics = doc.tables["identification"][0]["metrics"]
    assert {PIXEL_KEYS["Pixels loc. (m)"], PIXEL_KEYS["Simulated loc. (m)"]} <= set(metrics)


def test_robot_success_rate_leaves_false_positives_out():
    import numpy as np

    from lookalike.bench.pixels import robot_success_rate

    truth = [np.array([0, 1, -1]), np.array([-1, 1])]
    predicted = [np.array([0, 0, -1]), np.array([-1, 1])]
    assert robot_success_rate(predicted, truth) == 2 / 3  # robots 0 ok, 1 wrong, 1 ok; the two -1 not counted
    assert math.isnan(robot_success_rate([np.array([-1])], [np.array([-1])]))
