import cv2
import numpy as np
from typer.testing import CliRunner

from lookalike.cli import app
from lookalike.vision.heading import HeadingClassifier
from lookalike.vision.hog_cascade import HogCascade

runner = CliRunner()


def test_train_detector_from_folder_and_refusals(tmp_path):
    rng = np.random.default_rng(0)
    data = tmp_path / "data"
    (data / "positives").mkdir(parents=True)
    (data / "negatives").mkdir()
    for i in range(40):  # a bright upright bar on noise
        img = rng.normal(100, 12, (64, 32)).astype(np.float32)
        img[8:56, 10:22] += 90
        cv2.imwrite(str(data / "positives" / f"p{i}.png"), np.clip(img, 0, 255).astype(np.uint8))
    for i in range(4):
        img = rng.normal(100, 12, (120, 160, 3))
        y, x = rng.integers(0, 80), rng.integers(0, 120)
        img[y : y + 30, x : x + 30] += 60
        cv2.imwrite(str(data / "negatives" / f"n{i}.png"), np.clip(img, 0, 255).astype(np.uint8))
    out = tmp_path / "det.npz"
    res = runner.invoke(app, ["train-detector", "--data", str(data), "-o", str(out), "--stages", "2",
                              "--negatives", "200", "--copies", "1"])
    assert res.exit_code == 0, res.output
    model = HogCascade.load(out)
    assert 1 <= len(model.stages) <= 2
    res = runner.invoke(app, ["train-detector", "--data", str(tmp_path / "nothing"), "-o", str(out)])
    assert res.exit_code != 0 and "positives" in res.output
    (data / "positives" / "bad.png").write_bytes(b"not an image")
    res = runner.invoke(app, ["train-detector", "--data", str(data), "-o", str(out)])
    assert res.exit_code != 0 and "not a readable image" in res.output


def test_train_detector_refuses_rendering_options_with_data(tmp_path):
    """--frames and --validation-frames were accepted with --data and ignored (no rendering, no held-out choice)."""
    (tmp_path / "data" / "positives").mkdir(parents=True)
    out = tmp_path / "det.npz"
    res = runner.invoke(app, ["train-detector", "--data", str(tmp_path / "data"), "-o", str(out), "--frames", "50",
                              "--validation-frames", "20"])
    assert res.exit_code == 2 and "--frames, --validation-frames: only without --data" in res.output, res.output
    assert not out.exists()


def test_train_detector_on_rendered_frames(tmp_path):
    out = tmp_path / "det.npz"
    res = runner.invoke(app, ["train-detector", "-o", str(out), "--frames", "8", "--stages", "2",
                              "--negatives", "150", "--copies", "0", "--validation-frames", "3"])
    assert res.exit_code == 0, res.output
    assert "held-out (3 frames): kept" in " ".join(res.output.split())
    assert len(HogCascade.load(out).stages) >= 1
    res = runner.invoke(app, ["train-detector", "-o", str(out), "--validation-frames", "-1"])
    assert res.exit_code != 0 and "--validation-frames" in res.output


def test_train_heading_reports_error(tmp_path):
    out = tmp_path / "heading.npz"
    res = runner.invoke(app, ["train-heading", "-o", str(out), "--frames", "12", "--test-frames", "3",
                              "--folds", "2"])
    assert res.exit_code == 0, res.output
    assert "held-out mean absolute heading error" in res.output
    model = HeadingClassifier.load(out)
    assert model.support.shape[1] == len(model.mean)
    res = runner.invoke(app, ["train-heading", "-o", str(out), "--frames", "0"])
    assert res.exit_code != 0 and "--frames" in res.output


def test_train_heading_with_too_few_frames_names_the_option(tmp_path):
    """It said 'heading_rad: need >= 6 samples over >= 2 classes, got 5', naming neither option nor robots."""
    out = tmp_path / "h.npz"
    res = runner.invoke(app, ["train-heading", "-o", str(out), "--frames", "1", "--test-frames", "0"])
    assert res.exit_code == 2 and "--frames 1: " in res.output and "give more --frames or fewer --folds" in res.output
    assert not out.exists()
