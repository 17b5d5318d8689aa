"""``lookalike track`` writes each row's identity confidence in column 7 and prints the doubtful ranges."""

from pathlib import Path

import numpy as np
from typer.testing import CliRunner

from lookalike.cli import app
from lookalike.io import read_mot, write_mot
from lookalike.sim import BoxSceneConfig, simulate_boxes
from lookalike.trackers.offline.confidence import assignment_confidence

runner = CliRunner()


def _det_file(tmp_path: Path) -> Path:
    scene = simulate_boxes(BoxSceneConfig(frames=30, seed=3))
    rows = [[f.index + 1, -1, *box, score, -1, -1, -1]
            for f in scene.frames for box, score in zip(f.detections.xywh, f.detections.score)]
    return write_mot(tmp_path / "seq" / "det" / "det.txt", np.array(rows))


def _rows(path: Path) -> np.ndarray:
    t = read_mot(path)
    return np.column_stack([t.frame, t.track_id, t.xywh, t.conf, -np.ones((len(t), 3))])


def test_track_writes_confidence_and_prints_doubtful_ranges(tmp_path):
    det = _det_file(tmp_path)
    out = tmp_path / "tracks.txt"
    result = runner.invoke(app, ["track", str(det), "-t", "boxtrack", "-o", str(out)])
    assert result.exit_code == 0, result.output
    assert "doubtful: " in result.output
    rows = _rows(out)
    assert len(rows) and (rows[:, 6] >= 0).all() and (rows[:, 6] <= 1).all()
    np.testing.assert_allclose(rows[:, 6], assignment_confidence(rows, 30.0), atol=6e-4)  # seqinfo-less: 30/s


def test_offline_closed_set_and_folders_get_it_too(tmp_path):
    _det_file(tmp_path / "all")
    result = runner.invoke(app, ["track", str(tmp_path / "all"), "-t", "boxtrack", "--targets", "4", "--offline",
                                 "-o", str(tmp_path / "res")])
    assert result.exit_code == 0, result.output
    rows = _rows(tmp_path / "res" / "seq.txt")
    assert len(rows) and (rows[:, 6] >= 0).all() and (rows[:, 6] <= 1).all()
    assert "doubtful: " in result.output
