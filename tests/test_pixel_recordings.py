"""``lookalike record-pixels`` writes the pixel pipeline's detections of rendered robots as labelled
recordings (renderer truth) that read back as robot sequences and score with the LSTM."""

import numpy as np
import pytest
from typer.testing import CliRunner

pytest.importorskip("cv2", reason="rendering and the detector need OpenCV (the 'vision' extra)")

from lookalike.bench.pixel_recordings import recording_seeds, score_identifier  # noqa: E402
from lookalike.cli import app  # noqa: E402
from lookalike.io.robot_sequences import read_robot_sequence  # noqa: E402


def test_record_pixels_writes_readable_labelled_recordings(tmp_path):
    r = CliRunner().invoke(app, ["record-pixels", "-o", str(tmp_path), "--preset", "m3n2", "--sequences", "1",
                                 "--frames", "6", "--seed", "700000"])
    assert r.exit_code == 0, r.output
    (path,) = sorted(tmp_path.glob("*.labelled.jsonl"))
    assert path.name == f"pixels-m3n2-{recording_seeds('m3n2', 1, 700000)[0]}.labelled.jsonl"
    rec = read_robot_sequence(path)
    a = rec.arrays
    assert len(rec) == 6 and a.det_valid.shape[1] == rec.config.max_detections
    labels = a.det_label[a.det_valid]
    assert ((labels >= -1) & (labels < rec.config.n_agents)).all()
    assert np.isfinite(a.det_position[a.det_valid]).all()
    rate, n = score_identifier([rec], "lstm")
    assert n == int(a.det_valid.sum()) and (n == 0 or 0.0 <= rate <= 1.0)


def test_record_pixels_refuses_an_unknown_preset(tmp_path):
    r = CliRunner().invoke(app, ["record-pixels", "-o", str(tmp_path), "--preset", "m99"])
    assert r.exit_code == 2 and "--preset" in r.output


def test_record_pixels_refuses_more_detections_than_the_team_keeps(tmp_path):
    r = CliRunner().invoke(app, ["record-pixels", "-o", str(tmp_path), "--preset", "m3n2", "--max-detections", "4"])
    assert r.exit_code == 2 and "--max-detections 4" in r.output and "M=3" in r.output
    assert not list(tmp_path.glob("*.labelled.jsonl"))
