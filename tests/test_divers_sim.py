"""Diver scenarios: determinism, ground truth, detector model, rendering, absences."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from lookalike.sim.divers import (
    SCENARIOS,
    VALIDATION_SCENARIOS,
    DetectorModel,
    DiverScenario,
    detection_quality,
    scenario,
    simulate_divers,
)


def short(sc: DiverScenario, frames: int = 120) -> DiverScenario:
    return dataclasses.replace(sc, frames=frames)


def test_eight_named_scenarios_distinct_from_validation() -> None:
    names = [s.name for s in SCENARIOS]
    assert len(SCENARIOS) >= 8 and len(set(names)) == len(names)
    assert {s.n_divers for s in SCENARIOS} >= {2, 3, 4} and any(s.pool for s in SCENARIOS)
    assert not {s.seed for s in SCENARIOS} & {s.seed for s in VALIDATION_SCENARIOS}
    assert scenario("pool_pair").pool
    with pytest.raises(ValueError, match="unknown diver scenario"):
        scenario("nope")


def test_deterministic_per_seed() -> None:
    sc = short(SCENARIOS[1])
    a, b = simulate_divers(sc), simulate_divers(sc)
    assert np.array_equal(a.gt, b.gt)
    assert np.array_equal(a.image(50), b.image(50))
    fa, fb = a.frames(), b.frames()
    assert all(np.array_equal(x.detections.xywh, y.detections.xywh) for x, y in zip(fa, fb))
    c = simulate_divers(dataclasses.replace(sc, seed=sc.seed + 1))
    assert not np.array_equal(a.gt, c.gt)


def test_ground_truth_is_motchallenge_and_inside_the_image() -> None:
    sc = SCENARIOS[3]
    scene = simulate_divers(sc)
    gt = scene.gt
    assert gt.shape[1] == 9
    assert (gt[:, 0] >= 1).all() and (gt[:, 0] <= sc.frames).all()
    assert set(np.unique(gt[:, 1]).astype(int)) <= set(range(1, sc.n_divers + 1))
    w, h = sc.image_size
    assert (gt[:, 2] >= 0).all() and (gt[:, 2] + gt[:, 4] <= w + 1e-6).all() and (gt[:, 3] + gt[:, 5] <= h + 1e-6).all()
    assert ((gt[:, 8] >= 0) & (gt[:, 8] <= 1)).all()
    for i in range(1, sc.n_divers + 1):  # one box per diver per frame
        frames = gt[gt[:, 1] == i, 0]
        assert len(frames) == len(np.unique(frames))
    # long absences: some diver is missing for 30+ consecutive frames and comes back
    gaps = [np.diff(np.sort(gt[gt[:, 1] == i, 0])).max(initial=0) for i in range(1, sc.n_divers + 1)]
    assert max(gaps) >= 30


def test_box_shape_oscillates_with_strokes() -> None:
    scene = simulate_divers(short(SCENARIOS[6], 100))
    rows = scene.gt[scene.gt[:, 1] == 1]
    aspect = rows[:, 4] / rows[:, 5]
    assert np.std(np.diff(aspect)) > 0.01


def test_detector_recall_and_precision_are_controllable() -> None:
    scene = simulate_divers(short(SCENARIOS[2], 150))
    good = scene.frames(DetectorModel(recall=0.95, false_positives=0.05), seed=1)
    poor = scene.frames(DetectorModel(recall=0.5, false_positives=1.5), seed=1)
    dp_good, dr_good = detection_quality(good, scene.gt)
    dp_poor, dr_poor = detection_quality(poor, scene.gt)
    assert dr_good > dr_poor + 0.2 and dp_good > dp_poor + 0.2
    labels = np.concatenate([f.detections.label for f in poor])
    assert (labels == -1).any() and (labels > 0).any()
    with pytest.raises(ValueError, match="recall"):
        DetectorModel(recall=0.0)


def test_rendered_frame() -> None:
    sc = short(SCENARIOS[4], 10)
    scene = simulate_divers(sc)
    img = scene.image(5)
    assert img.shape == (sc.image_size[1], sc.image_size[0], 3) and img.dtype == np.uint8
    rows = scene.gt[scene.gt[:, 0] == 6]
    if len(rows):  # a diver differs from the water around it
        x, y, w, h = rows[0, 2:6].astype(int)
        assert img[y : y + h, x : x + w].std() > 3
    with pytest.raises(ValueError, match="n_divers"):
        DiverScenario(name="x", n_divers=9)
