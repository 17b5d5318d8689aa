import numpy as np
import pytest

from lookalike.vision.hog_cascade import CascadeConfig, HogCascade, block_pool, nms, train_cascade, window_features
from lookalike.vision.hog_features import augment_windows, integral_maps, orientation_maps


def rect_sums(integral, x0, y0, x1, y1):
    """Sums over rectangles ``[y0, y1) × [x0, x1)`` (px) of ``integral (c, h+1, w+1)``."""
    return integral[:, y1, x1] - integral[:, y0, x1] - integral[:, y1, x0] + integral[:, y0, x0]


def _window(rng, positive):
    """66x34 grey window (1-px margin): a bright upright bar (positive) or random clutter."""
    w = rng.normal(100, 12, (66, 34)).astype(np.float32)
    if positive:
        w[8:58, 11:23] += 90
    else:
        y, x = rng.integers(0, 50), rng.integers(0, 20)
        w[y : y + 16, x : x + 14] += rng.uniform(-80, 80)
    return w


def test_integral_histogram_matches_direct_sums():
    rng = np.random.default_rng(0)
    g = rng.uniform(0, 255, (20, 30)).astype(np.float32)
    maps = orientation_maps(g)
    np.testing.assert_allclose(maps.sum(axis=0)[1:-1, 1:-1], np.hypot(
        g[1:-1, 2:] - g[1:-1, :-2], g[2:, 1:-1] - g[:-2, 1:-1]), rtol=1e-5)
    ii = integral_maps(maps)
    np.testing.assert_allclose(rect_sums(ii, 3, 2, 11, 9), maps[:, 2:9, 3:11].sum(axis=(1, 2)), rtol=1e-6)


def test_train_detect_save_load(tmp_path):
    rng = np.random.default_rng(1)
    cfg = CascadeConfig(stages=3, negatives_per_stage=300, min_height_px=64, max_height_px=64)
    pos = np.array([_window(rng, True) for _ in range(150)])
    inner = augment_windows(pos[:, 1:-1, 1:-1], 1, rng, cutout=0.3)
    pos = np.concatenate([pos, np.pad(inner, ((0, 0), (1, 1), (1, 1)), mode="edge")])
    model = train_cascade(pos, lambda n, r: np.array([_window(r, False) for _ in range(n)]), cfg, seed=0)
    assert 1 <= len(model.stages) <= 3
    blocks = block_pool(cfg.window_px, cfg.cell_px)
    test_pos = window_features(np.array([_window(rng, True) for _ in range(100)]), blocks)
    test_neg = window_features(np.array([_window(rng, False) for _ in range(300)]), blocks)
    assert model.classify(test_pos)[0].mean() > 0.9
    assert model.classify(test_neg)[0].mean() < 0.1
    # A scene with one bar: found at the right place, scored as a probability.
    scene = rng.normal(100, 12, (120, 160)).astype(np.float32)
    scene[30:80, 71:83] += 90
    det = model(np.clip(scene, 0, 255).astype(np.uint8))
    assert len(det) >= 1
    best = det.xywh[np.argmax(det.score)]
    assert abs(best[0] + best[2] / 2 - 77) < 8 and abs(best[1] + best[3] / 2 - 55) < 10
    assert ((det.score > 0) & (det.score < 1)).all()
    path = model.save(tmp_path / "m.npz")
    again = HogCascade.load(path)
    np.testing.assert_array_equal(again(scene.clip(0, 255).astype(np.uint8)).xywh, det.xywh)


def test_bad_model_files_are_refused(tmp_path):
    junk = tmp_path / "junk.npz"
    junk.write_bytes(b"not a model")
    with pytest.raises(ValueError, match="not a readable HOG cascade"):
        HogCascade.load(junk)
    text = tmp_path / "README.md"
    text.write_text("# notes\n")
    with pytest.raises(ValueError) as caught:  # numpy's own text said to trust the file and unpickle it
        HogCascade.load(text)
    assert str(caught.value) == f"{text}: not a readable HOG cascade model (not an .npz archive)"
    other = tmp_path / "other.npz"
    np.savez(other, header=np.array('{"format": "something-else", "version": 1}'))
    with pytest.raises(ValueError, match="not a HOG cascade model"):
        HogCascade.load(other)
    newer = tmp_path / "newer.npz"
    np.savez(newer, header=np.array('{"format": "lookalike-hog-cascade", "version": 99}'))
    with pytest.raises(ValueError, match="version 99"):
        HogCascade.load(newer)


def test_nms_keeps_best_of_overlapping():
    boxes = np.array([[0, 0, 10, 20], [1, 1, 10, 20], [50, 50, 10, 20]], float)
    keep = nms(boxes, np.array([0.5, 0.9, 0.7]), 0.4)
    assert keep.tolist() == [1, 2]


def test_merge_nms_suppresses_parts_and_averages_shifted_copies():
    from lookalike.vision.hog_cascade import merge_nms

    boxes = np.array([[0, 0, 10, 20], [2, 0, 10, 20], [2, 2, 5, 8], [50, 50, 10, 20]], float)
    out, keep = merge_nms(boxes, np.array([0.9, 0.8, 0.95, 0.7]), 0.3, 0.3)
    # The part box scores best: it is kept and suppresses both whole windows (overlap is measured against
    # the smaller box), and is not averaged with them (IoU 0.2 at most).
    assert keep.tolist() == [2, 3]
    out, keep = merge_nms(boxes[[0, 1, 3]], np.array([0.9, 0.8, 0.7]), 0.3, 0.3)
    assert keep.tolist() == [0, 2]
    np.testing.assert_allclose(out[0], [1, 0, 10, 20])
    np.testing.assert_allclose(out[1], [50, 50, 10, 20])


def test_cell_histograms_equal_summed_orientation_maps():
    from lookalike.vision.hog_features import cell_histograms

    g = np.random.default_rng(5).uniform(0, 255, (37, 50)).astype(np.float32)
    ref = orientation_maps(g)[:, :36, :48].reshape(9, 9, 4, 12, 4).sum(axis=(2, 4))
    np.testing.assert_allclose(cell_histograms(g, 4), ref, rtol=1e-5, atol=1e-3)


def test_hard_negative_search_stops_when_cascade_is_good_enough():
    rng = np.random.default_rng(6)
    cfg = CascadeConfig(stages=10, negatives_per_stage=200, max_draws_per_stage=6, target_false_positive_rate=0.05)
    pos = np.array([_window(rng, True) for _ in range(120)])
    draws = []

    def negatives(n, r):
        draws.append(n)
        return np.array([_window(r, False) for _ in range(n)])

    messages = []
    model = train_cascade(pos, negatives, cfg, seed=0, progress=lambda k, m: messages.append(m))
    assert len(model.stages) < cfg.stages
    assert "stopped" in messages[-1]
    assert len(draws) <= cfg.max_draws_per_stage * (len(model.stages) + 1)
    with pytest.raises(ValueError, match="target_false_positive_rate"):
        CascadeConfig(target_false_positive_rate=1.5)


def test_scene_mining_finds_hard_negatives_away_from_true_boxes():
    from lookalike.vision.hog_cascade import _mine_scenes

    rng = np.random.default_rng(7)
    cfg = CascadeConfig(stages=4, negatives_per_stage=200, min_height_px=64, max_height_px=80)
    pos = np.array([_window(rng, True) for _ in range(120)])
    scenes = []
    for _ in range(6):
        scene = rng.normal(100, 12, (100, 140)).astype(np.float32)
        scene[20:70, 20:32] += 90  # the target
        scene[30:90, 90:100] += 70  # a look-alike distractor bar that random clutter never shows
        scenes.append((scene, np.array([[10.0, 13.0, 32.0, 64.0]])))
    messages = []
    model = train_cascade(pos, lambda n, r: np.array([_window(r, False) for _ in range(n)]), cfg, seed=0,
                          progress=lambda k, m: messages.append(m), scenes=scenes)
    assert any("mined from scenes" in m and "(0 mined" not in m for m in messages)
    xywh, margin = model.windows(scenes[0][0])
    assert len(xywh) == len(margin)
    det = model(scenes[0][0].clip(0, 255).astype(np.uint8))
    assert len(det) <= len(xywh)
    # Mined windows never overlap a true box by more than hard_negative_max_iou.
    one_stage = HogCascade(cfg, model.blocks, model.stages[:1])
    found = _mine_scenes(one_stage, scenes, cfg, 50, np.random.default_rng(0))
    assert found.shape[1:] == (66, 34)
    truth_crop = scenes[0][0][13 - 1 : 13 + 65, 10 - 1 : 10 + 33]
    assert not any(np.allclose(f, truth_crop, atol=1.0) for f in found)


@pytest.mark.parametrize("edit, problem", [
    (lambda a: {**a, "s0_index": a["s0_index"] + 100_000}, "feature indices"),
    (lambda a: {**a, "s0_weight": a["s0_weight"] * np.nan}, "NaN or infinity"),
    (lambda a: {**a, "s0_weight": a["s0_weight"][:1]}, "differ in shape"),
])
def test_stages_that_do_not_fit_are_refused(tmp_path, edit, problem):
    from lookalike.vision.pipeline import MODELS_DIR, SHIPPED_MODELS

    with np.load(MODELS_DIR / SHIPPED_MODELS["detector"]) as data:
        arrays = {k: data[k] for k in data.files}
    np.savez(tmp_path / "bad.npz", **edit(arrays))
    with pytest.raises(ValueError, match=f"bad.npz: corrupt HOG cascade model \\(stage 0: .*{problem}"):
        HogCascade.load(tmp_path / "bad.npz")


@pytest.mark.parametrize("negatives", [0, -5])
def test_a_cascade_needs_negatives(negatives):
    with pytest.raises(ValueError, match="negatives_per_stage .*must be >= 1"):
        CascadeConfig(negatives_per_stage=negatives)


def test_an_interrupted_model_save_leaves_the_earlier_file_whole(tmp_path, monkeypatch):
    """Model files (and the detection probability map) were written in place: a Ctrl-C mid-save left half an
    archive under the model's name."""
    from lookalike.vision.detection_probability import DetectionProbability
    from lookalike.vision.model_file import load_model_file, save_model_file

    path = save_model_file(tmp_path / "m.npz", "fmt", 1, {"k": 1}, {"a": np.arange(5.0)})
    before = path.read_bytes()

    def cut_short(file, *args, **kwargs):
        file.write(before[:40])
        raise KeyboardInterrupt

    monkeypatch.setattr(np, "savez_compressed", cut_short)
    with pytest.raises(KeyboardInterrupt):
        save_model_file(path, "fmt", 1, {"k": 2}, {"a": np.arange(6.0)})
    monkeypatch.undo()
    assert path.read_bytes() == before and [p.name for p in tmp_path.iterdir()] == ["m.npz"]
    assert load_model_file(path, "fmt", 1, "model")[0]["k"] == 1
    DetectionProbability((0.0, 1.0), (0.1, 0.9)).save(tmp_path / "p.json")
    (tmp_path / "p-earlier.json").hardlink_to(tmp_path / "p.json")  # a second name: kept if the save renames
    DetectionProbability((0.0, 1.0), (0.2, 0.8)).save(tmp_path / "p.json")
    assert DetectionProbability.load(tmp_path / "p-earlier.json").probability == (0.1, 0.9)
    assert DetectionProbability.load(tmp_path / "p.json").probability == (0.2, 0.8)
