"""Held-out selection of a HOG cascade's prefix and pyramid start, and its probability calibration."""

import numpy as np
import pytest

from lookalike.vision.hog_cascade import CascadeConfig, HogCascade, train_cascade
from lookalike.vision.hog_select import HeldOutScene, match_detections, select_stages
from tests.test_hog_cascade import _window


def _scene(rng, x):
    """A 120x160 scene with one bar (50 px tall) at column ``x`` and its target box."""
    img = rng.normal(100, 12, (120, 160)).astype(np.float32)
    img[30:80, x : x + 12] += 90
    return np.clip(img, 0, 255).astype(np.uint8), np.array([[x - 10.0, 25.0, 32.0, 60.0]])


def test_match_detections_hits_excuses_and_false_positives():
    truth = np.array([[0.0, 0, 10, 20]])
    ignore = np.array([[50.0, 0, 10, 20]])
    boxes = np.array([[1.0, 1, 10, 20], [0.0, 0, 10, 20], [50.0, 1, 10, 20], [100.0, 0, 10, 20]])
    hit, excused = match_detections(boxes, truth, ignore)
    # one-to-one: the second box on the same target is a false positive, not a second hit
    assert hit.tolist() == [True, False, False, False] or hit.tolist() == [False, True, False, False]
    assert excused.tolist() == [False, False, True, False]
    hit, excused = match_detections(np.zeros((0, 4)), truth, ignore)
    assert hit.shape == excused.shape == (0,)
    with pytest.raises(ValueError, match="iou"):
        match_detections(boxes, truth, ignore, iou=0.0)


def test_select_stages_scores_prefixes_and_calibrates(tmp_path):
    rng = np.random.default_rng(3)
    cfg = CascadeConfig(stages=4, negatives_per_stage=300, min_height_px=64, max_height_px=80)
    pos = np.array([_window(rng, True) for _ in range(150)])
    model = train_cascade(pos, lambda n, r: np.array([_window(r, False) for _ in range(n)]), cfg, seed=0)
    scenes = [HeldOutScene(*_scene(rng, int(x)), np.zeros((0, 4))) for x in rng.integers(20, 130, 6)]
    chosen, tried = select_stages(model, scenes, min_stages=1)
    n = len(model.stages)
    prefixes = [t for t in tried if t.min_height_px == cfg.min_height_px]
    assert [t.stages for t in prefixes] == list(range(n, 0, -1))
    best = max(t.f1 for t in prefixes)
    assert len(chosen.stages) in {t.stages for t in prefixes if t.f1 == best}
    assert all(0 <= t.precision <= 1 and 0 <= t.recall <= 1 for t in tried)
    # the kept model finds the bars, its scores are probabilities and it survives a save/load
    det = chosen(scenes[0].image)
    assert len(det) >= 1 and ((det.score > 0) & (det.score < 1)).all()
    assert chosen.calibration[0] > 0
    again = HogCascade.load(chosen.save(tmp_path / "chosen.npz"))
    assert (len(again.stages), again.config, again.calibration) == (len(chosen.stages), chosen.config,
                                                                    chosen.calibration)
    np.testing.assert_array_equal(again(scenes[0].image).xywh, det.xywh)
    with pytest.raises(ValueError, match="scenes"):
        select_stages(model, [])
