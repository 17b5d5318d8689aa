"""ONNX detection models (``vision.onnx_detector``) and ``track --video V --detector FILE.onnx`` end to end.

The models are built here with the ``onnx`` helper API: constant heads for the decoding of each
layout, and a tiny "darkness grid" detector that finds dark divers in pool water.
"""

from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

onnx = pytest.importorskip("onnx")
pytest.importorskip("onnxruntime")
from onnx import TensorProto, helper, numpy_helper  # noqa: E402

from lookalike.cli import app  # noqa: E402
from lookalike.io import read_mot  # noqa: E402
from lookalike.sim.divers import DetectorModel, DiverScenario, simulate_divers  # noqa: E402
from lookalike.vision.onnx_detector import (  # noqa: E402
    OnnxDetector,
    OnnxDetectorConfig,
    config_from_settings,
    letterbox,
)
from lookalike.viz.video import VideoWriter  # noqa: E402

runner = CliRunner()


def _save(graph, path: Path) -> Path:
    model = helper.make_model(graph, opset_imports=[helper.make_opsetid("", 13)])
    model.ir_version = 8
    onnx.checker.check_model(model)
    onnx.save(model, str(path))
    return path


def _constant_model(path: Path, outputs: dict[str, np.ndarray], size: int = 64) -> Path:
    """A model ignoring its image input ``(1, 3, size, size)`` and returning ``outputs``."""
    x = helper.make_tensor_value_info("images", TensorProto.FLOAT, [1, 3, size, size])
    nodes, outs, inits = [], [], []
    for k, (name, value) in enumerate(outputs.items()):
        # out = value + 0 * mean(x): keeps the input wired into the graph
        inits.append(numpy_helper.from_array(value.astype(np.float32), f"c{k}"))
        nodes.append(helper.make_node("ReduceMean", ["images"], [f"m{k}"], keepdims=0))
        nodes.append(helper.make_node("Mul", [f"m{k}", f"z{k}"], [f"mz{k}"]))
        inits.append(numpy_helper.from_array(np.zeros((), np.float32), f"z{k}"))
        nodes.append(helper.make_node("Add", [f"c{k}", f"mz{k}"], [name]))
        outs.append(helper.make_tensor_value_info(name, TensorProto.FLOAT, list(value.shape)))
    return _save(helper.make_graph(nodes, "constant", [x], outs, inits), path)


def _darkness_grid_model(path: Path, size: int = 128, cell: int = 16) -> Path:
    """YOLO-layout ``(1, 5, N)`` detector: one box per ``cell`` grid cell, scored by how dark the cell is."""
    g = size // cell
    cy, cx = np.mgrid[0:g, 0:g] * cell + cell / 2
    boxes = np.stack([cx.ravel(), cy.ravel(), np.full(g * g, 48.0), np.full(g * g, 24.0)])[None]
    x = helper.make_tensor_value_info("images", TensorProto.FLOAT, [1, 3, size, size])
    y = helper.make_tensor_value_info("output0", TensorProto.FLOAT, [1, 5, g * g])
    inits = [numpy_helper.from_array(boxes.astype(np.float32), "boxes"),
             numpy_helper.from_array(np.array(0.4, np.float32), "level"),
             numpy_helper.from_array(np.array(4.0, np.float32), "gain"),
             numpy_helper.from_array(np.array([1, 1, g * g], np.int64), "shape")]
    nodes = [
        helper.make_node("ReduceMean", ["images"], ["grey"], axes=[1], keepdims=1),
        helper.make_node("Sub", ["level", "grey"], ["dark0"]),
        helper.make_node("Relu", ["dark0"], ["dark"]),
        helper.make_node("AveragePool", ["dark"], ["pooled"], kernel_shape=[cell, cell], strides=[cell, cell]),
        helper.make_node("Mul", ["pooled", "gain"], ["score4"]),
        helper.make_node("Reshape", ["score4", "shape"], ["score"]),
        helper.make_node("Concat", ["boxes", "score"], ["output0"], axis=1),
    ]
    return _save(helper.make_graph(nodes, "darkness_grid", [x], [y], inits), path)


def test_letterbox_centres_and_scales():
    img = np.zeros((50, 100, 3), np.uint8)
    out, r, (dx, dy) = letterbox(img, (64, 64))
    assert out.shape == (64, 64, 3) and r == pytest.approx(0.64) and (dx, dy) == (0.0, 16.0)
    assert (out[:16] == 114).all() and (out[16:48] == 0).all()


def test_yolo_rows_and_columns_decode_to_frame_pixels(tmp_path):
    # input 64x64; a 128x64 frame letterboxes with r = 0.5, dy = 16
    rows = np.array([[32.0, 32.0, 20.0, 10.0, 0.1, 0.9],  # class 1
                     [33.0, 32.0, 20.0, 10.0, 0.8, 0.1],  # class 0, overlaps the first (other class)
                     [10.0, 40.0, 8.0, 8.0, 0.2, 0.05]])  # below threshold
    rows = np.vstack([rows, np.zeros((5, 6))])  # real heads have more boxes than values per box
    image = np.zeros((64, 128, 3), np.uint8)
    for name, out in (("rows", rows[None]), ("cols", rows.T[None])):
        det = OnnxDetector(_constant_model(tmp_path / f"{name}.onnx", {"out": out}))(image)
        assert len(det) == 2
        assert det.label.tolist() == [1, 0] and det.score.tolist() == pytest.approx([0.9, 0.8])
        np.testing.assert_allclose(det.xywh[0], [44.0, 22.0, 40.0, 20.0])
    only0 = OnnxDetector(tmp_path / "rows.onnx", OnnxDetectorConfig(classes=(0,)))(image)
    assert only0.label.tolist() == [0] and len(only0) == 1


def test_nms_and_objectness_and_ssd(tmp_path):
    image = np.zeros((64, 64, 3), np.uint8)
    rows = np.array([[32.0, 32.0, 20.0, 20.0, 0.9, 1.0], [33.0, 32.0, 20.0, 20.0, 0.5, 1.0],
                     [10.0, 10.0, 6.0, 6.0, 0.2, 1.0], *np.zeros((4, 6))])
    det = OnnxDetector(_constant_model(tmp_path / "v5.onnx", {"out": rows[None]}),
                       OnnxDetectorConfig(layout="yolo-obj"))(image)
    assert det.score.tolist() == pytest.approx([0.9])  # the overlapping copy is suppressed, 0.2 < 0.25
    boxes = np.array([[[0.1, 0.2, 0.3, 0.4], [0.5, 0.5, 0.9, 0.9]]])
    scores = np.array([[[0.1, 0.7], [0.6, 0.2]]])
    det = OnnxDetector(_constant_model(tmp_path / "ssd.onnx", {"boxes": boxes, "scores": scores}))(image)
    assert det.label.tolist() == [1, 0]
    np.testing.assert_allclose(det.xywh, [[6.4, 12.8, 12.8, 12.8], [32.0, 32.0, 25.6, 25.6]], atol=1e-4)
    yx = OnnxDetector(tmp_path / "ssd.onnx", config_from_settings(["box_order=yxyx", "score=0.65"]))(image)
    np.testing.assert_allclose(yx.xywh, [[12.8, 6.4, 12.8, 12.8]], atol=1e-4)


def test_settings_and_bad_models_are_refused(tmp_path):
    cfg = config_from_settings(["score=0.4", "classes=0,2", "input_size=320x240", "layout=yolo-obj", "rgb=no"])
    assert cfg.score_threshold == 0.4 and cfg.classes == (0, 2) and cfg.input_size == (320, 240) and not cfg.rgb
    for bad in (["nope=1"], ["score=high"], ["layout=retina"]):
        with pytest.raises(ValueError):
            config_from_settings(bad)
    junk = tmp_path / "junk.onnx"
    junk.write_bytes(b"not a model")
    with pytest.raises(ValueError, match="junk.onnx"):
        OnnxDetector(junk)
    two = _constant_model(tmp_path / "two.onnx", {"a": np.zeros((1, 3, 4)), "b": np.zeros((1, 3, 2))})
    with pytest.raises(ValueError, match="layout"):
        OnnxDetector(two, OnnxDetectorConfig(layout="yolo"))


@pytest.fixture(scope="module")
def pool_video(tmp_path_factory):
    root = tmp_path_factory.mktemp("onnx_video")
    sc = DiverScenario(name="t", n_divers=2, frames=30, image_size=(320, 240), focal_px=260.0, seed=5, pool=True,
                       attenuation=0.06, turbidity=0.05, blur_per_m=0.1, leave_rate=0.0,
                       detector=DetectorModel(recall=1.0, false_positives=0.0))
    scene = simulate_divers(sc)
    with VideoWriter(root / "pool.mp4", fps=10) as writer:
        for k in range(sc.frames):
            writer.write(scene.image(k))
    return root / "pool.mp4", scene.gt, _darkness_grid_model(root / "dark.onnx")


@pytest.mark.parametrize(("tracker", "features"), [("sort", "video"), ("diversort", "learned")])
def test_track_video_with_onnx_detector_end_to_end(pool_video, tmp_path, tracker, features):
    video, gt, model = pool_video
    out = tmp_path / "tracks.txt"
    r = runner.invoke(app, ["track", "--video", str(video), "--detector", str(model), "--blob", "score=0.15",
                            "-t", tracker, "--features", features, "-o", str(out),
                            "--save-detections", str(tmp_path / "tracks.det.txt")])
    assert r.exit_code == 0, r.output
    det = read_mot(tmp_path / "tracks.det.txt")
    assert len(det) >= 30 and det.conf.min() >= 0.15
    # every detection's centre lies near a diver of its frame (the model finds dark divers, not water)
    near = 0
    for frame, box in zip(det.frame, det.xywh):
        g = gt[gt[:, 0] == frame, 2:6]
        c = box[:2] + box[2:] / 2
        near += bool(len(g)) and bool(((c[0] > g[:, 0] - 20) & (c[0] < g[:, 0] + g[:, 2] + 20)
                                       & (c[1] > g[:, 1] - 20) & (c[1] < g[:, 1] + g[:, 3] + 20)).any())
    assert near >= 0.9 * len(det)
    assert len(read_mot(out)) > 0
    assert "frames/s" in r.output
    assert ("--set appearance_threshold=" in r.output) == (features == "learned")


def test_track_video_onnx_detector_errors(pool_video, tmp_path):
    video, _, model = pool_video
    missing = runner.invoke(app, ["track", "--video", str(video), "--detector", str(tmp_path / "none.onnx"),
                                  "-o", str(tmp_path / "t.txt")])
    assert missing.exit_code == 2 and "none.onnx" in missing.output
    bad = runner.invoke(app, ["track", "--video", str(video), "--detector", str(model), "--blob", "colour=red",
                              "-o", str(tmp_path / "t.txt")])
    assert bad.exit_code == 2 and "colour" in bad.output
    feats = runner.invoke(app, ["track", "--video", str(video), "--detector", str(model), "--features", "deep",
                                "-o", str(tmp_path / "t.txt")])
    assert feats.exit_code == 2 and "--features" in feats.output
