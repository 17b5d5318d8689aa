"""The human benchmark's result files (``label --benchmark``) and their row in seed A's Table III."""

from __future__ import annotations

import json

import pytest
from typer.testing import CliRunner

from lookalike.bench.table3 import HUMAN, NO_VALUE, human_row, table3_table
from lookalike.cli import app
from lookalike.io.robot_sequences import write_robot_sequence
from lookalike.sim import preset, simulate_robots
from lookalike.viz.label import open_label_app, read_human_results
from lookalike.viz.label.human import (
    HumanResult,
    check_labeller,
    human_result_path,
    read_human_result,
    write_human_result,
)

runner = CliRunner()


def _result(frames_scored: int, detections: int, correct: int, labeller: str = "ann", n_agents: int = 2,
            max_detections: int = 3) -> HumanResult:
    return HumanResult(sequence="s.jsonl", labeller=labeller, n_agents=n_agents, max_detections=max_detections,
                       n_frames=1000, started_at=100.0, finished_at=400.0, duration_s=300.0,
                       frames_scored=frames_scored, detections_scored=detections, correct=correct, unset=0,
                       success_rate=correct / detections, success_rate_all=None)


def test_finished_session_writes_a_result_file(tmp_path):
    seq_path = tmp_path / "m3n2-000001.jsonl"
    seq = simulate_robots(preset("m3n2"), 30, 1)
    write_robot_sequence(seq_path, seq)
    label_app = open_label_app(seq_path, benchmark=True, labeller="ann-1")
    truth = seq.true_labels()
    label_app.store.start_benchmark(now=10.0)
    for k in range(5):
        for j, t in enumerate(truth[k]):
            label_app.store.set_label(k, j, int(t))
    bench = label_app.finish_benchmark()
    path = tmp_path / "m3n2-000001.human-ann-1.json"
    assert label_app.result_path == path and path.is_file()
    (result,) = read_human_results(tmp_path)
    assert result.labeller == "ann-1" and result.sequence == seq_path.name
    assert (result.n_agents, result.max_detections, result.n_frames) == (2, 3, 30)
    assert result.duration_s == pytest.approx(bench["duration_s"]) and result.duration_s > 0
    assert result.success_rate == bench["success_rate"] and result.correct == result.detections_scored


def test_labeller_ids_and_bad_files_are_refused(tmp_path):
    assert check_labeller("a.b_c-1") == "a.b_c-1"
    for bad in ("", "../x", "a b", "-a", "x" * 65):
        with pytest.raises(ValueError, match="labeller"):
            check_labeller(bad)
    assert human_result_path(tmp_path / "s.jsonl", "ann", tmp_path / "out") == tmp_path / "out" / "s.human-ann.json"
    path = write_human_result(tmp_path / "s.human-ann.json", _result(400, 700, 600))
    assert read_human_result(path) == _result(400, 700, 600)
    doc = json.loads(path.read_text())
    for change in ({"format": "x"}, {"correct": 900}, {"labeller": "a b"}, {"success_rate": 2.0}):
        (tmp_path / "bad.human-x.json").write_text(json.dumps({**doc, **change}))
        with pytest.raises(ValueError, match="bad.human-x.json"):
            read_human_result(tmp_path / "bad.human-x.json")
    del doc["duration_s"]
    (tmp_path / "bad.human-x.json").write_text(json.dumps(doc))
    with pytest.raises(ValueError, match="missing duration_s"):
        read_human_result(tmp_path / "bad.human-x.json")


def test_human_row_pools_sessions_by_the_longest_length_worked_through():
    results = [_result(250, 100, 90), _result(450, 100, 80), _result(1000, 200, 150), _result(100, 50, 50)]
    row = human_row(results, [200, 400, 800], "Total, 3200 frames (%)")
    assert row == {"Tracker": HUMAN, "200 frames (%)": 90.0, "400 frames (%)": 80.0, "800 frames (%)": 75.0,
                   "Total, 3200 frames (%)": round(100 * 370 / 450, 2), "Localisation error (m)": NO_VALUE}
    assert human_row(results[:1], [400], "Total")["400 frames (%)"] == NO_VALUE


def test_table3_merges_fabricated_results_of_the_same_setup(tmp_path):
    write_human_result(tmp_path / "a.human-ann.json", _result(250, 100, 90))
    write_human_result(tmp_path / "b.human-bob.json", _result(250, 100, 70, labeller="bob", n_agents=3,
                                                              max_detections=5))
    sessions: list[dict] = []
    rows = table3_table(["m3n2"], ["kalman_ha"], 1, 120, 5, "ours", [50, 100], 1, human=tmp_path,
                        sessions=sessions)
    assert [r["Tracker"] for r in rows] == ["kalman_ha", HUMAN]
    assert rows[1]["100 frames (%)"] == 90.0 and rows[1]["50 frames (%)"] == NO_VALUE
    assert [s["Labeller"] for s in sessions] == ["ann"] and sessions[0]["s/frame"] == 1.2


def test_cli_label_export_and_bench_ident_human(tmp_path):
    seq_path = tmp_path / "m3n2-000002.jsonl"
    write_robot_sequence(seq_path, simulate_robots(preset("m3n2"), 120, 2))
    label_app = open_label_app(seq_path, benchmark=True, labeller="cli")
    label_app.store.start_benchmark()
    first = next(k for k, n in enumerate(label_app.store.counts) if n)
    label_app.store.set_label(first, 0, 0)
    label_app.store.finish_benchmark(label_app.truth)  # finished, but no result file written yet
    res = runner.invoke(app, ["label", str(seq_path), "--benchmark", "--labeller", "cli", "--export"])
    assert res.exit_code == 0, res.output
    assert (tmp_path / "m3n2-000002.human-cli.json").is_file()
    bad = runner.invoke(app, ["label", str(seq_path), "--benchmark", "--labeller", "a b", "--export"])
    assert bad.exit_code == 2 and "--labeller" in bad.output
    res = runner.invoke(app, ["bench", "ident", "--recordings", str(tmp_path), "--trackers", "kalman_ha",
                              "--lengths", "60", "--draws", "1"])
    assert res.exit_code == 0, res.output
    assert "human" in res.output and "Human benchmark sessions" in res.output
    res = runner.invoke(app, ["bench", "ident", "--human", str(tmp_path / "none")])
    assert res.exit_code == 2 and "--human" in res.output


def test_an_explicit_human_folder_without_a_matching_result_says_why_there_is_no_human_row(tmp_path):
    empty = tmp_path / "empty"
    empty.mkdir()
    with pytest.raises(ValueError, match=r"--human: no result files \(\*\.human-\*\.json"):
        table3_table(["m3n2"], ["kalman_ha"], 1, 60, 5, "ours", [30], 1, human=empty)
    other = tmp_path / "other"
    write_human_result(other / "b.human-bob.json", _result(50, 100, 70, labeller="bob", n_agents=3, max_detections=5))
    with pytest.raises(ValueError, match=r"are for M=5, N=3, not for the table's set-up\(s\) M=3, N=2"):
        table3_table(["m3n2"], ["kalman_ha"], 1, 60, 5, "ours", [30], 1, human=other)
