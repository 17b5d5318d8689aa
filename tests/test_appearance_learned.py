"""The learned diver appearance model: training scenes, the shipped ONNX embedding, selection by name,
and a tiny training run exported to ONNX."""

from __future__ import annotations

import json
import re

import numpy as np
import pytest

pytest.importorskip("onnxruntime")

from lookalike.sim.diver_render import TEAM  # noqa: E402
from lookalike.sim.divers import SCENARIOS, VALIDATION_SCENARIOS, DiverScenario, simulate_divers  # noqa: E402
from lookalike.sim.divers_run import diver_extractor, matched_thresholds  # noqa: E402
from lookalike.sim.divers_train import training_scenarios  # noqa: E402
from lookalike.vision.appearance import HandcraftedFeatures, crop_boxes  # noqa: E402
from lookalike.vision.appearance_onnx import LEARNED_MODEL, OnnxAppearance  # noqa: E402


def test_training_scenes_have_new_divers_and_disjoint_seeds() -> None:
    train = training_scenarios(6, frames=20)
    seeds = {sc.seed for sc in train}
    assert not seeds & {sc.seed for sc in SCENARIOS + VALIDATION_SCENARIOS}
    for sc in train:
        assert sc.looks is not None and len(sc.looks) == sc.n_divers
        assert not set(sc.looks) & set(TEAM)
    scene = simulate_divers(train[0])
    assert scene.image(5).shape == (480, 640, 3) and len(scene.gt)
    with pytest.raises(ValueError, match="n_divers"):
        DiverScenario(name="x", n_divers=3, looks=TEAM[:2])


def test_crop_boxes_width_height() -> None:
    img = np.zeros((100, 200, 3), np.uint8)
    img[:, 100:] = 255
    crops = crop_boxes(img, np.array([[50.0, 10.0, 100.0, 50.0]]), (64, 32))
    assert crops.shape == (1, 32, 64, 3)
    assert crops[0, :, :30].max() == 0 and crops[0, :, 34:].min() == 255


def test_shipped_model_embeds_and_tells_divers_apart() -> None:
    meta = json.loads(LEARNED_MODEL.with_suffix(".json").read_text())
    assert LEARNED_MODEL.stat().st_size < 2_000_000
    assert set(meta["training"]["scenario_seeds"]).isdisjoint({sc.seed for sc in SCENARIOS + VALIDATION_SCENARIOS})
    ex = diver_extractor("learned")
    assert isinstance(ex, OnnxAppearance) and ex.dim == meta["output"]["dim"] == 32
    sc = DiverScenario(name="t", n_divers=3, frames=40, pool=True, attenuation=0.06, turbidity=0.05, blur_per_m=0.1,
                       leave_rate=0.0, seed=3)
    scene = simulate_divers(sc)
    feats, labels = [], []
    for k in range(0, 40, 4):
        rows = scene.gt[(scene.gt[:, 0] == k + 1) & (scene.gt[:, 8] > 0.5)]
        feats.append(ex(scene.image(k), rows[:, 2:6]))
        labels.append(rows[:, 1])
    f, lab = np.vstack(feats), np.concatenate(labels)
    assert len(np.unique(lab)) >= 2
    assert np.allclose(np.linalg.norm(f, axis=1), 1.0)
    d = 1 - f @ f.T
    same = lab[:, None] == lab[None, :]
    off = ~np.eye(len(f), dtype=bool)
    assert d[same & off].mean() < d[~same].mean()
    assert ex(scene.image(0), np.zeros((0, 4))).shape == (0, 32)


def test_extractor_names() -> None:
    assert matched_thresholds(HandcraftedFeatures(), "diversort") == {}
    learned = diver_extractor("learned")
    assert matched_thresholds(learned, "sort") == {}
    stored = matched_thresholds(learned, "diversort")  # from the shipped JSON, no rendering
    assert set(stored) == {"appearance_threshold", "long_term_threshold", "recovery_threshold"}
    assert 0 < stored["appearance_threshold"] < stored["long_term_threshold"] < 1
    with pytest.raises(ValueError, match="handcrafted, learned or FILE.onnx"):
        diver_extractor("deep")
    with pytest.raises(FileNotFoundError):
        diver_extractor("missing.onnx")


@pytest.mark.parametrize("channels, dtype, says", [(1, "FLOAT", "1 channel"), (3, "UINT8", "tensor(uint8)")])
def test_an_embedding_whose_input_lookalike_cannot_feed_is_named(tmp_path, channels, dtype, says) -> None:
    onnx = pytest.importorskip("onnx")
    from onnx import TensorProto, helper

    x = helper.make_tensor_value_info("crops", getattr(TensorProto, dtype), ["n", channels, 32, 64])
    y = helper.make_tensor_value_info("embedding", TensorProto.FLOAT, ["n", channels])
    nodes = [helper.make_node("Cast", ["crops"], ["f"], to=TensorProto.FLOAT),
             helper.make_node("ReduceMean", ["f"], ["embedding"], keepdims=0, axes=[2, 3])]
    model = helper.make_model(helper.make_graph(nodes, "odd_crops", [x], [y]),
                              opset_imports=[helper.make_opsetid("", 13)])
    model.ir_version = 8
    path = tmp_path / "odd.onnx"
    onnx.save(model, str(path))
    with pytest.raises(ValueError, match=f"odd.onnx: .*{re.escape(says)}"):
        OnnxAppearance(path)


def test_a_device_torch_cannot_use_is_refused_before_any_work(tmp_path, monkeypatch) -> None:
    torch = pytest.importorskip("torch")
    from typer.testing import CliRunner

    from lookalike.cli import app
    from lookalike.learn.appearance_train import AppearanceTrainConfig, train_appearance
    from lookalike.learn.device import torch_device

    monkeypatch.setattr(torch.cuda, "is_available", lambda: False)
    assert torch_device("auto").type == "cpu"
    for device, says in (("gpu", "choose cpu, cuda"), ("cuda", "this PyTorch sees no CUDA device")):
        with pytest.raises(ValueError, match=f"device '{device}': {says}"):
            train_appearance(AppearanceTrainConfig(scenarios=1, frames=10, epochs=1, device=device), tmp_path / "m")
        r = CliRunner().invoke(app, ["train-appearance", "-o", str(tmp_path / "m"), "--device", device])
        assert r.exit_code == 2 and f"--device '{device}': {says}" in r.output and "Traceback" not in r.output
    assert not (tmp_path / "m").exists()


def test_tiny_training_run_exports_onnx(tmp_path) -> None:
    pytest.importorskip("torch")
    from lookalike.learn.appearance_train import AppearanceTrainConfig, train_appearance

    config = AppearanceTrainConfig(scenarios=1, frames=20, every=5, epochs=1, channels=4, embedding=8,
                                   validation_every=60, match_thresholds=False)
    info = train_appearance(config, tmp_path, log=lambda _: None)
    assert (tmp_path / "diver_reid.onnx").exists() and info["training"]["identities"] >= 2
    assert json.loads((tmp_path / "diver_reid.json").read_text())["config"]["embedding"] == 8
    ex = OnnxAppearance(tmp_path / "diver_reid.onnx")
    assert ex.dim == 8 and ex.crop_size == (64, 32)


def test_retraining_into_a_model_folder_measures_its_own_thresholds_and_an_interruption_keeps_the_old(
        tmp_path, monkeypatch) -> None:
    """The new model's thresholds were read from the earlier model's JSON beside it (silently wrong for track and
    bench divers), and Ctrl-C after the export left the new ONNX beside the earlier JSON."""
    pytest.importorskip("torch")
    import lookalike.learn.appearance_train as appearance_train
    import lookalike.sim.divers_run as divers_run
    from lookalike.learn.appearance_data import CropSet
    from lookalike.learn.appearance_train import AppearanceTrainConfig, train_appearance

    rng = np.random.default_rng(0)  # crops of three made-up divers (rendering them is not under test)
    crops = CropSet(rng.integers(0, 256, (12, 32, 64, 3), dtype=np.uint8), np.repeat([10, 20, 30], 4))
    monkeypatch.setattr(appearance_train, "diver_crops", lambda *args, **kwargs: crops)

    earlier = {"model": "diver_reid.onnx", "matched_thresholds": {"deepsort": {"max_cosine_distance": 0.987}}}
    (tmp_path / "diver_reid.onnx").write_bytes(b"the earlier model")
    (tmp_path / "diver_reid.json").write_text(json.dumps(earlier))
    config = AppearanceTrainConfig(scenarios=1, frames=10, every=5, epochs=1, channels=4, embedding=8,
                                   validation_every=60)

    def interrupted(*args, **kwargs):
        raise KeyboardInterrupt

    with monkeypatch.context() as m:
        m.setattr(divers_run, "matched_thresholds", interrupted)
        with pytest.raises(KeyboardInterrupt):
            train_appearance(config, tmp_path, log=lambda _: None)
    assert (tmp_path / "diver_reid.onnx").read_bytes() == b"the earlier model"
    assert json.loads((tmp_path / "diver_reid.json").read_text()) == earlier
    assert sorted(p.name for p in tmp_path.iterdir()) == ["diver_reid.json", "diver_reid.onnx"]
    distances = np.linspace(0.0, 0.5, 101)  # (the measured distances, cheap: the matching itself is not under test)
    monkeypatch.setattr(divers_run, "_reference_distances", lambda: distances)
    monkeypatch.setattr(divers_run, "_distances_of", lambda extractor: distances)
    train_appearance(config, tmp_path, log=lambda _: None)
    stored = json.loads((tmp_path / "diver_reid.json").read_text())["matched_thresholds"]["deepsort"]
    assert stored["max_cosine_distance"] != 0.987
    assert OnnxAppearance(tmp_path / "diver_reid.onnx").dim == 8
