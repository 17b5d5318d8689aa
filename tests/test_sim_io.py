"""Robot sequences on disk (JSON Lines) and the ``lookalike simulate`` command."""

from __future__ import annotations

import dataclasses
import json

import numpy as np
import pytest
from typer.testing import CliRunner

from lookalike.cli import app
from lookalike.io.robot_sequences import read_robot_sequence, write_robot_sequence
from lookalike.sim import preset, simulate_robots


def test_round_trip_is_exact(tmp_path):
    seq = simulate_robots(preset("m5n3"), 120, seed=4)
    back = read_robot_sequence(write_robot_sequence(tmp_path / "s.jsonl", seq))
    assert back.config == seq.config and back.seed == 4
    for f in dataclasses.fields(seq.arrays):
        if f.name == "reports":
            continue
        assert np.array_equal(getattr(seq.arrays, f.name), getattr(back.arrays, f.name)), f.name
    for f in dataclasses.fields(seq.arrays.reports):
        assert np.array_equal(getattr(seq.arrays.reports, f.name), getattr(back.arrays.reports, f.name)), f.name
    a, b = seq.frame(60), back.frame(60)
    assert np.array_equal(a.detections.position, b.detections.position)
    assert np.array_equal(a.beacons.t_sent, b.beacons.t_sent)


def test_malformed_files(tmp_path):
    empty = tmp_path / "e.jsonl"
    empty.write_text("")
    with pytest.raises(ValueError, match="empty"):
        read_robot_sequence(empty)
    wrong = tmp_path / "w.jsonl"
    wrong.write_text('{"format": "other"}\n')
    with pytest.raises(ValueError, match="lookalike-robots"):
        read_robot_sequence(wrong)
    path = write_robot_sequence(tmp_path / "t.jsonl", simulate_robots(preset("m3n2"), 10, seed=1))
    path.write_text("\n".join(path.read_text().splitlines()[:-1]) + "\n")
    with pytest.raises(ValueError, match="frames"):
        read_robot_sequence(path)


def _beacons(rows):
    return next(r["beacons"] for r in rows[1:] if r["beacons"]["agent_id"])


@pytest.mark.parametrize("edit, problem", [
    (lambda rows: rows[3].update(time=float("nan")), "time must be a finite number"),
    (lambda rows: _beacons(rows)["heading"].__setitem__(0, float("nan")), "NaN or infinity in a report"),
    (lambda rows: _beacons(rows)["heading"].append(0.0), "differ in length"),
    (lambda rows: _beacons(rows)["agent_id"].__setitem__(0, 0.5), "agent ids must be whole numbers from 0 to 1"),
    (lambda rows: _beacons(rows)["agent_id"].__setitem__(0, 2), "agent ids must be whole numbers from 0 to 1"),
    (lambda rows: rows[3]["truth"]["observer"].__setitem__(0, float("inf")), "observer's pose"),
])
def test_reports_times_and_poses_are_checked(tmp_path, edit, problem):
    path = write_robot_sequence(tmp_path / "s.jsonl", simulate_robots(preset("m3n2"), 40, seed=5))
    rows = [json.loads(line) for line in path.read_text().splitlines()]
    edit(rows)
    path.write_text("".join(json.dumps(r) + "\n" for r in rows))
    with pytest.raises(ValueError, match=f"s.jsonl:\\d+: malformed frame record \\(frame \\d+: .*{problem}"):
        read_robot_sequence(path)


def test_simulate_command(tmp_path):
    result = CliRunner().invoke(app, ["simulate", "--preset", "m3n2", "--frames", "30", "--sequences", "2",
                                      "--seed", "5", "-o", str(tmp_path)])
    assert result.exit_code == 0, result.output
    files = sorted(tmp_path.glob("*.jsonl"))
    assert [f.name for f in files] == ["m3n2-000005.jsonl", "m3n2-000006.jsonl"]
    seq = read_robot_sequence(files[0])
    assert len(seq) == 30 and seq.config.n_agents == 2
    bad = CliRunner().invoke(app, ["simulate", "--preset", "nope", "-o", str(tmp_path)])
    assert bad.exit_code != 0


@pytest.mark.parametrize("column, value", [("heading", [0.5]), ("score", [0.5]), ("position", [[1.0], [2.0]])])
def test_detection_columns_of_another_length_are_refused(tmp_path, column, value):
    path = write_robot_sequence(tmp_path / "s.jsonl", simulate_robots(preset("m3n2"), 40, seed=5))
    rows = [json.loads(line) for line in path.read_text().splitlines()]
    row = next(r for r in rows[1:] if len(r["detections"]["label"]) == 2)
    row["detections"][column] = value
    path.write_text("".join(json.dumps(r) + "\n" for r in rows))
    with pytest.raises(ValueError, match="malformed frame record .*2 labels but position, heading and score"):
        read_robot_sequence(path)
