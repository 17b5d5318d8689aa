"""``lookalike train --recordings`` reads rosbag2 folders with labels (``simulate --bag``'s truth records) beside
``*.labelled.jsonl`` files, and refuses a bag without labels in one line."""

import json
from pathlib import Path

import pytest
from typer.testing import CliRunner

pytest.importorskip("rosbags", reason="bags need the 'ros' extra")

from lookalike.io.rosbag import _typestore, read_labelled_bag, write_bag  # noqa: E402
from lookalike.io.rosmap import IMU  # noqa: E402
from lookalike.sim import preset, simulate_robots  # noqa: E402

runner = CliRunner()


def _bags(folder: Path, n: int = 3) -> list[Path]:
    return [write_bag(folder / f"run-{k}", simulate_robots(preset("m3n2"), 90 + 30 * k, 600 + k)) for k in range(n)]


def test_a_bag_gives_the_labels_it_was_written_with(tmp_path):
    seq = simulate_robots(preset("m7n4"), 40, 3)
    back = read_labelled_bag(write_bag(tmp_path / "run", seq))
    assert (back.arrays.det_label == seq.arrays.det_label).all()
    assert (back.config.n_agents, back.config.max_detections) == (4, 7)


def test_train_recordings_fine_tunes_on_bags(tmp_path):
    pytest.importorskip("torch", reason="training needs torch (the 'train' extra)")
    from lookalike.cli import app

    _bags(tmp_path / "rec")
    out = tmp_path / "out"
    r = runner.invoke(app, ["train", "--recordings", str(tmp_path / "rec"), "-o", str(out), "--steps", "2",
                            "--sequence-length", "150", "--batch-size", "2", "--validate-every", "1"])
    assert r.exit_code == 0, r.output
    split = json.loads((out / "model.json").read_text())["info"]["recordings"]
    assert sorted(split["training"] + split["validation"]) == ["run-0", "run-1", "run-2"]


def test_a_bag_without_labels_is_refused_in_one_line(tmp_path):
    from rosbags.rosbag2 import Writer

    from lookalike.cli import app

    folder = tmp_path / "rec"
    _bags(folder, n=1)
    with Writer(folder / "unlabelled", version=8) as writer:
        writer.add_connection("/robot_0/imu", IMU, typestore=_typestore())
    r = runner.invoke(app, ["train", "--recordings", str(folder), "-o", str(tmp_path / "out"), "--steps", "1"])
    assert r.exit_code != 0 and "unlabelled: no labels" in r.output
    assert len([line for line in r.output.splitlines() if line.strip()]) == 1, r.output
    (folder / "broken").mkdir()
    (folder / "broken" / "metadata.yaml").write_text("not: [a bag")
    r = runner.invoke(app, ["train", "--recordings", str(folder), "-o", str(tmp_path / "out"), "--steps", "1"])
    assert r.exit_code != 0 and "broken" in r.output
