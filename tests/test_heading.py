import json

import numpy as np
import pytest

from lookalike.learn.vision_train import rendered_heading_samples
from lookalike.vision.heading import (
    HeadingClassifier,
    HeadingConfig,
    class_centres,
    heading_class,
    heading_features,
    mean_abs_error_deg,
    train_heading,
)

SMALL = HeadingConfig(patch_px=(16, 16), cell_px=8, folds=2, c_grid=(1.0, 10.0), gamma_grid=(1.0,))


def _synthetic(n, rng, config=SMALL):
    """Features whose first 20 columns encode cos/sin of the heading, all with noise."""
    d = 2 * 36 + 2 if config is SMALL else None
    h = rng.uniform(-np.pi, np.pi, n)
    f = rng.normal(0, 0.3, (n, d))
    f[:, 0:20:2] += 3 * np.cos(h)[:, None]
    f[:, 1:20:2] += 3 * np.sin(h)[:, None]
    return f, h


def test_classes_and_centres():
    assert heading_class(np.radians([0, 17, 19, -19, 180, -180, 359])).tolist() == [0, 0, 1, 9, 5, 5, 0]
    c = class_centres(10)
    assert c.shape == (10,) and (c > -np.pi).all() and (c <= np.pi).all()
    assert np.allclose(np.degrees(c[[0, 1, 5, 9]]), [0, 36, 180, -36])
    assert mean_abs_error_deg(np.radians([179.0, 10.0]), np.radians([-179.0, 0.0])) == pytest.approx(6.0)


def test_numpy_inference_matches_scikit_learn_and_probabilities_are_coherent():
    from sklearn.svm import SVC

    rng = np.random.default_rng(0)
    f, h = _synthetic(300, rng)
    model = train_heading(f, h, SMALL, seed=0)
    x = (f - model.mean) / model.scale
    ref = SVC(kernel="rbf", C=model.c, gamma=model.gamma, decision_function_shape="ovo").fit(x, heading_class(h))
    ft, ht = _synthetic(100, rng)
    xt = (ft - model.mean) / model.scale
    np.testing.assert_allclose(model.decision_values(ft), ref.decision_function(xt), rtol=1e-6, atol=1e-6)
    est = model.estimate(ft)
    np.testing.assert_allclose(est.prob.sum(axis=1), 1.0, atol=1e-9)
    assert (est.prob >= 0).all() and est.prob.shape == (100, 10)
    assert np.array_equal(est.label, est.prob.argmax(axis=1))
    assert (est.heading_rad > -np.pi).all() and (est.heading_rad <= np.pi).all()
    # At least the sector's own spread, and confident (low spread) rows more accurate than unsure ones.
    assert (est.heading_std_rad >= np.radians(36) / np.sqrt(12) - 1e-9).all()
    assert mean_abs_error_deg(est.heading_rad, ht) < 15.0
    err = np.abs(np.degrees(np.angle(np.exp(1j * (est.heading_rad - ht)))))
    sure = est.heading_std_rad <= np.median(est.heading_std_rad)
    assert err[sure].mean() <= err[~sure].mean()


def test_features_of_boxes_in_grey_and_colour_images():
    rng = np.random.default_rng(1)
    img = rng.integers(0, 255, (60, 80, 3), dtype=np.uint8)
    boxes = np.array([[10, 5, 20, 40], [-5, 30, 30, 40]], float)  # the second one leaves the image
    f = heading_features(img, boxes, SMALL)
    assert f.shape == (2, 2 * 36 + 2) and np.isfinite(f).all()
    np.testing.assert_allclose(f[0, -2:], [20 / 80, 25 / 60])
    assert heading_features(img[..., 0], boxes, SMALL).shape == (2, 74)
    assert heading_features(img, np.zeros((0, 4)), SMALL).shape == (0, 74)
    with pytest.raises(ValueError, match="xywh"):
        heading_features(img, np.array([[0, 0, 0, 10]]), SMALL)
    with pytest.raises(ValueError, match="xywh"):
        heading_features(img, np.array([1, 2, 3]), SMALL)
    with pytest.raises(ValueError, match="image"):
        heading_features(np.zeros((0, 0, 3), np.uint8), boxes, SMALL)


def test_train_rejects_bad_input():
    rng = np.random.default_rng(2)
    f, h = _synthetic(40, rng)
    with pytest.raises(ValueError, match="features"):
        train_heading(f[:, :10], h, SMALL)
    with pytest.raises(ValueError, match="heading_rad"):
        train_heading(f, h[:-1], SMALL)
    with pytest.raises(ValueError, match="heading_rad"):
        train_heading(f, np.zeros(40), SMALL)  # a single class
    with pytest.raises(ValueError, match="cell"):
        HeadingConfig(patch_px=(8, 8), cell_px=8)


def test_save_load_round_trip_and_refusals(tmp_path):
    rng = np.random.default_rng(3)
    f, h = _synthetic(120, rng)
    model = train_heading(f, h, SMALL, seed=1)
    path = model.save(tmp_path / "heading.npz")
    again = HeadingClassifier.load(path)
    np.testing.assert_allclose(again.estimate(f).prob, model.estimate(f).prob, atol=1e-4)  # float32 support vectors
    np.testing.assert_array_equal(again.estimate(f).label, model.estimate(f).label)
    assert again.config == model.config
    junk = tmp_path / "junk.npz"
    junk.write_bytes(b"garbage")
    with pytest.raises(ValueError, match="not a readable heading model"):
        HeadingClassifier.load(junk)
    with pytest.raises(ValueError, match="not a readable heading model"):
        HeadingClassifier.load(tmp_path / "missing.npz")
    other = tmp_path / "other.npz"
    np.savez(other, header=np.array(json.dumps({"format": "lookalike-hog-cascade", "version": 1})))
    with pytest.raises(ValueError, match="not a heading model"):
        HeadingClassifier.load(other)
    with np.load(path) as data:
        arrays = {k: data[k] for k in data.files}
    header = json.loads(str(arrays.pop("header")))
    np.savez(tmp_path / "newer.npz", header=np.array(json.dumps({**header, "version": 99})), **arrays)
    with pytest.raises(ValueError, match="version 99"):
        HeadingClassifier.load(tmp_path / "newer.npz")
    # Arrays that do not fit the configuration (e.g. trained with another patch size) are refused.
    bad = {**header, "config": {**header["config"], "patch_px": [24, 24]}}
    np.savez(tmp_path / "mismatch.npz", header=np.array(json.dumps(bad)), **arrays)
    with pytest.raises(ValueError, match="corrupt heading model"):
        HeadingClassifier.load(tmp_path / "mismatch.npz")
    arrays.pop("support")
    np.savez(tmp_path / "truncated.npz", header=np.array(json.dumps(header)), **arrays)
    with pytest.raises(ValueError, match="corrupt heading model"):
        HeadingClassifier.load(tmp_path / "truncated.npz")
    with pytest.raises(ValueError, match="features"):
        model.estimate(np.zeros((2, 5)))


def test_rendered_robots_tiny_training_beats_chance():
    from lookalike.geometry.camera import Camera

    cam = Camera.default(320, 240)  # small frames render fast
    cfg = HeadingConfig(folds=3, c_grid=(10.0,), gamma_grid=(0.25, 1.0))
    f, h = rendered_heading_samples(50, seed=11, config=cfg, camera=cam)
    ft, ht = rendered_heading_samples(12, seed=12, config=cfg, camera=cam)
    assert len(f) >= 150 and len(ft) >= 30 and f.shape[1] == ft.shape[1]
    f2, _ = rendered_heading_samples(2, seed=11, config=cfg, camera=cam)
    np.testing.assert_allclose(f2, f[: len(f2)], rtol=1e-5, atol=1e-6)  # deterministic by seed (SIMD rounding aside)
    model = train_heading(f, h, cfg, seed=0)
    # Chance is 90 degrees; ~170 renders already do much better (~1300 reach ~12 degrees, see the note).
    err = mean_abs_error_deg(model.estimate(ft).heading_rad, ht)
    assert err < 50.0, err


def test_rare_class_still_trains():
    rng = np.random.default_rng(4)
    f, h = _synthetic(60, rng)
    h[0] = np.radians(108.0)  # class 3 gets a single sample (absent from some folds)
    f[0, 0:20:2], f[0, 1:20:2] = 3 * np.cos(h[0]), 3 * np.sin(h[0])
    model = train_heading(f, h, SMALL, seed=0)
    np.testing.assert_allclose(model.estimate(f).prob.sum(axis=1), 1.0, atol=1e-9)


@pytest.mark.parametrize("name", ["mean", "support", "prob_a"])
def test_non_finite_arrays_are_refused(tmp_path, name):
    from lookalike.vision.pipeline import MODELS_DIR, SHIPPED_MODELS

    with np.load(MODELS_DIR / SHIPPED_MODELS["heading"]) as data:
        arrays = {k: data[k] for k in data.files}
    arrays[name] = np.where(np.arange(arrays[name].size).reshape(arrays[name].shape) == 0, np.nan, arrays[name])
    np.savez(tmp_path / "bad.npz", **arrays)
    with pytest.raises(ValueError, match=r"bad.npz: corrupt heading model \(holds NaN or infinity\)"):
        HeadingClassifier.load(tmp_path / "bad.npz")
