"""Fine-tuning on labelled recordings: the split is by recording, windows and validation arrays have the
training's shapes, and ``lookalike train --recordings`` fine-tunes, records its split and refuses bad input
in one line."""

import json
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from lookalike.io.robot_sequences import write_robot_sequence
from lookalike.learn.data import IGNORE
from lookalike.learn.recordings import RecordingSampler, split_recordings, validation_arrays
from lookalike.sim import preset, simulate_robots
from lookalike.trackers.lstm.encoding import EncodingSpec

runner = CliRunner()


def _recordings(folder: Path, setup: str = "m3n2", n: int = 3, frames: int = 90) -> list[Path]:
    world = preset(setup)
    return [write_robot_sequence(folder / f"rec-{k}.labelled.jsonl", simulate_robots(world, frames + 30 * k, 500 + k))
            for k in range(n)]


def test_split_is_by_recording_and_deterministic():
    train, val = split_recordings(8, 0.25, seed=3)
    assert len(val) == 2 and len(train) == 6 and not set(train) & set(val)
    assert sorted(train + val) == list(range(8))
    assert split_recordings(8, 0.25, seed=3) == (train, val)
    assert all(split_recordings(2, 0.9))  # always one of each
    with pytest.raises(ValueError, match="at least 2 recordings"):
        split_recordings(1, 0.25)


def test_windows_and_validation_arrays_have_training_shapes():
    world = preset("m3n2")
    spec = EncodingSpec(world.n_agents, world.max_detections, relative_headings=True)
    arrays = tuple(simulate_robots(world, t, 7 + t).arrays for t in (100, 200))
    sampler = RecordingSampler(spec, arrays)
    x, y = sampler(5, 150, np.random.default_rng(0))
    assert x.shape == (150, spec.n_inputs) and y.shape == (150, spec.n_slots)
    again = sampler(5, 150, np.random.default_rng(0))
    np.testing.assert_array_equal(x, again[0])
    long_x, long_y = sampler(5, 300, np.random.default_rng(0))  # longer than any recording: padded
    assert long_x.shape[0] == 300 and (long_y[200:] == IGNORE).all()
    vx, vy = validation_arrays(spec, arrays, bptt=150)
    assert vx.shape == (2, 300, spec.n_inputs) and (vy[0, 100:] == IGNORE).all()


def test_a_simulated_share_rehearses_the_recordings_world():
    world = preset("m3n2")
    spec = EncodingSpec(world.n_agents, world.max_detections, relative_headings=True)
    arrays = (simulate_robots(world, 150, 1).arrays,)
    only_sim = RecordingSampler(spec, arrays, world, sim_fraction=1.0)
    x, y = only_sim(11, 150, None)
    assert x.shape == (150, spec.n_inputs)
    assert not np.array_equal(x, RecordingSampler(spec, arrays)(11, 150, None)[0])
    with pytest.raises(ValueError, match="needs the world"):
        RecordingSampler(spec, arrays, None, sim_fraction=0.5)


@pytest.fixture
def app():
    pytest.importorskip("torch", reason="training needs torch (the 'train' extra)")
    from lookalike.cli import app

    return app


def test_train_recordings_fine_tunes_and_records_the_split(app, tmp_path):
    _recordings(tmp_path / "rec")
    _recordings(tmp_path / "test", n=1)
    out = tmp_path / "out"
    r = runner.invoke(app, ["train", "--recordings", str(tmp_path / "rec"), "-o", str(out), "--steps", "2",
                            "--sequence-length", "150", "--batch-size", "2", "--validate-every", "1",
                            "--test", str(tmp_path / "test"), "--mix-sim", "0.5"])
    assert r.exit_code == 0, r.output
    meta = json.loads((out / "model.json").read_text())
    split = meta["info"]["recordings"]
    assert len(split["validation"]) == 1 and len(split["training"]) == 2
    assert not set(split["validation"]) & set(split["training"])
    assert meta["info"]["config"]["init_from"].endswith("lstm_m3_n2.npz") and split["sim_fraction"] == 0.5
    assert "test recordings (1" in r.output and "fine-tuned" in r.output


@pytest.mark.parametrize("case", ["garbage", "empty", "other_setup", "single"])
def test_train_recordings_refuses_bad_input_in_one_line(app, tmp_path, case):
    folder = tmp_path / "rec"
    folder.mkdir()
    if case == "garbage":
        _recordings(folder, n=2, frames=30)
        (folder / "bad.labelled.jsonl").write_text("{not json\n")
        expected = "bad.labelled.jsonl"
    elif case == "empty":
        expected = "holds no"
    elif case == "other_setup":
        _recordings(folder, setup="m5n3", n=2, frames=30)
        expected = "recorded with N=3, M=5"
    else:
        _recordings(folder, n=1, frames=30)
        expected = "at least 2 recordings"
    from lookalike.trackers.lstm.weights import shipped_weights_path

    r = runner.invoke(app, ["train", "--recordings", str(folder), "-o", str(tmp_path / "out"), "--steps", "1",
                            "--sequence-length", "150", "--init-from", str(shipped_weights_path(2, 3))])
    assert r.exit_code == 2
    assert expected in r.output and "Traceback" not in r.output
    assert len(r.output.strip().splitlines()) == 1, r.output


def test_train_recordings_warns_of_a_recording_without_robots(app, tmp_path):
    """An export of a sequence nobody labelled (every detection a false positive) trained without a word."""
    import dataclasses

    from lookalike.sim import RobotSequence

    _recordings(tmp_path / "rec", n=2)
    sequence = simulate_robots(preset("m3n2"), 60, 77)
    arrays = dataclasses.replace(sequence.arrays, det_label=np.full_like(sequence.arrays.det_label, -1))
    write_robot_sequence(tmp_path / "rec" / "nobody.labelled.jsonl", RobotSequence(sequence.config, sequence.seed,
                                                                                    arrays))
    r = runner.invoke(app, ["train", "--recordings", str(tmp_path / "rec"), "-o", str(tmp_path / "out"), "--steps",
                            "1", "--sequence-length", "150", "--batch-size", "2"])
    assert r.exit_code == 0, r.output
    assert "nobody.labelled.jsonl: no detection is labelled as a robot" in r.output
    assert r.output.count("no detection is labelled") == 1


def test_train_recordings_simulates_the_measured_detector(app, tmp_path):
    _recordings(tmp_path / "rec")
    _recordings(tmp_path / "test", n=1)
    out = tmp_path / "out"
    args = ["train", "--recordings", str(tmp_path / "rec"), "-o", str(out), "--steps", "1",
            "--sequence-length", "150", "--batch-size", "2", "--mix-sim-fit"]
    r = runner.invoke(app, [*args, "--mix-sim", "0.5", "--test", str(tmp_path / "test")])
    assert r.exit_code == 0, r.output
    sensor = json.loads((out / "model.json").read_text())["info"]["recordings"]["sim_sensor"]
    assert sensor["heading_classes"] == 0 and sensor["fp_per_frame"] >= 0
    assert "detector measured on the training recordings" in r.output and "true robots" in r.output
    bad = runner.invoke(app, [*args, "-o", str(tmp_path / "bad")])
    assert bad.exit_code == 2 and "--mix-sim-fit needs" in bad.output


def test_train_recordings_validates_on_a_folder_of_its_own(app, tmp_path):
    _recordings(tmp_path / "rec", n=2)
    val = tmp_path / "val"
    val.mkdir()
    write_robot_sequence(val / "held.labelled.jsonl", simulate_robots(preset("m3n2"), 60, 900))
    out = tmp_path / "out"
    r = runner.invoke(app, ["train", "--recordings", str(tmp_path / "rec"), "-o", str(out), "--steps", "1",
                            "--sequence-length", "150", "--batch-size", "2", "--validation", str(val)])
    assert r.exit_code == 0, r.output
    split = json.loads((out / "model.json").read_text())["info"]["recordings"]
    assert split["training"] == ["rec-0.labelled.jsonl", "rec-1.labelled.jsonl"]
    assert split["validation"] == ["held.labelled.jsonl"] and split["validation_folder"] == str(val)
    bad = runner.invoke(app, ["train", "--recordings", str(tmp_path / "rec"), "-o", str(tmp_path / "bad"),
                              "--steps", "1", "--validation", str(tmp_path / "none")])
    assert bad.exit_code == 2 and "--validation" in bad.output


@pytest.mark.parametrize("option", ["--validation", "--test"])
def test_train_recordings_refuses_to_hold_out_its_training_recordings(app, tmp_path, option):
    _recordings(tmp_path / "rec", n=2)
    r = runner.invoke(app, ["train", "--recordings", str(tmp_path / "rec"), "-o", str(tmp_path / "out"), "--steps",
                            "1", "--sequence-length", "150", "--batch-size", "2", option, str(tmp_path / "rec")])
    assert r.exit_code == 2 and option in r.output and "holds 2 of the --recordings" in r.output, r.output
    assert not (tmp_path / "out" / "model.npz").exists()


def test_train_recordings_refuses_to_test_on_its_validation_recordings(app, tmp_path):
    """--test on the --validation folder scored the weights on the recordings they were chosen on, as a test."""
    _recordings(tmp_path / "rec", n=2)
    _recordings(tmp_path / "val", n=1)
    r = runner.invoke(app, ["train", "--recordings", str(tmp_path / "rec"), "-o", str(tmp_path / "out"), "--steps",
                            "1", "--sequence-length", "150", "--batch-size", "2", "--validation", str(tmp_path / "val"),
                            "--test", str(tmp_path / "val")])
    assert r.exit_code == 2 and "--test: " in r.output and "holds 1 of the --validation recordings" in r.output
    assert not (tmp_path / "out" / "model.npz").exists()
