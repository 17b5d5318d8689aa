"""Every ``--json`` validates against the shipped results schema (lookalike/io/results.schema.json)."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from typer.testing import CliRunner

from lookalike.cli import app
from lookalike.io.results import SCHEMA_ID, Results, metric_key, percent_row_metrics, schema

jsonschema = pytest.importorskip("jsonschema", reason="jsonschema is in the test extra")
runner = CliRunner()
DATA = Path(__file__).resolve().parents[1].parent / "shared" / "data"


def _valid(path: Path) -> dict:
    doc = json.loads(path.read_text())
    jsonschema.validate(doc, schema())
    assert doc["schema"] == SCHEMA_ID
    assert doc["header"]["lookalike_version"] and doc["header"]["command"].startswith("lookalike ")
    return doc


def _run(args: list[str]) -> None:
    res = runner.invoke(app, args)
    assert res.exit_code == 0, res.output


def test_schema_is_a_valid_json_schema_and_ships_with_the_package():
    jsonschema.Draft202012Validator.check_schema(schema())


def test_builder_refuses_percent_and_display_keys():
    doc = Results("bench x")
    with pytest.raises(ValueError, match="fraction"):
        doc.add("rows", dataset="m3n2", tracker="jpda", metrics={"success_rate": 93.1})
    with pytest.raises(ValueError, match="machine key"):
        doc.add("rows", dataset="m3n2", tracker="jpda", metrics={"Success rate (%)": 0.9})
    row = doc.add("rows", dataset="m3n2", tracker="jpda", metrics={"frames_per_s": float("inf"), "idsw": 3.0})
    assert row["metrics"] == {"frames_per_s": None, "idsw": 3}
    jsonschema.validate(doc.to_dict(), schema())


def test_printed_rows_become_fractions_with_machine_keys():
    assert metric_key("Localisation error (m)") == "localisation_error_m"
    assert metric_key("HOTA___AUC") == "hota_auc" and metric_key("Frames/s") == "frames_per_s"
    assert percent_row_metrics({"Setup": "M=3, N=2", "Success rate (%)": 93.1, "Detections": 5},
                               skip=("Setup",)) == {"success_rate": 0.931, "detections": 5}


def test_a_percent_in_a_document_fails_the_schema():
    doc = Results("bench x").to_dict()
    doc["tables"]["rows"] = [{"dataset": "m3n2", "sequence": None, "tracker": "jpda", "combined": False,
                              "metrics": {"idf1": 81.0}}]
    with pytest.raises(jsonschema.ValidationError):
        jsonschema.validate(doc, schema())


def test_bench_ident_shuffle_recovery_json(tmp_path):
    _run(["bench", "ident", "--setups", "m3n2", "--trackers", "kalman_ha2", "--sequences", "1", "--frames", "40",
          "--json", str(tmp_path / "i.json")])
    doc = _valid(tmp_path / "i.json")
    assert doc["header"]["kind"] == "bench ident" and doc["header"]["sequences"] == 1
    _run(["bench", "shuffle", "--setups", "m3n2", "--trackers", "kalman_ha2", "--sequences", "1", "--frames", "40",
          "--json", str(tmp_path / "s.json")])
    _valid(tmp_path / "s.json")
    _run(["bench", "recovery", "--setups", "m3n2", "--trackers", "kalman_ha2", "--sequences", "1", "--frames", "300",
          "--swap-at-s", "2", "--swap-s", "3", "--json", str(tmp_path / "r.json")])
    _valid(tmp_path / "r.json")


def test_eval_json(tmp_path):
    seq = tmp_path / "gt" / "SEQ-1"
    (seq / "gt").mkdir(parents=True)
    (seq / "gt" / "gt.txt").write_text("".join(f"{f},1,0,0,10,10,1,1,1\n" for f in range(1, 5)))
    (tmp_path / "res").mkdir()
    (tmp_path / "res" / "SEQ-1.txt").write_text("".join(f"{f},3,0,0,10,10,1,-1,-1,-1\n" for f in range(1, 5)))
    _run(["eval", "--gt", str(tmp_path / "gt"), "--results", str(tmp_path / "res"), "--json", str(tmp_path / "e.json")])
    doc = _valid(tmp_path / "e.json")
    rows = doc["tables"]["scores"]
    assert [(r["sequence"], r["combined"]) for r in rows] == [("SEQ-1", False), (None, True)]
    assert rows[1]["metrics"]["hota"] == pytest.approx(1.0, abs=1e-6)


def test_eval_json_unwritable_is_one_line_before_any_work(tmp_path):
    seq = tmp_path / "gt" / "SEQ-1"
    (seq / "gt").mkdir(parents=True)
    (seq / "gt" / "gt.txt").write_text("1,1,0,0,10,10,1,1,1\n")
    (tmp_path / "res").mkdir()
    (tmp_path / "res" / "SEQ-1.txt").write_text("1,3,0,0,10,10,1,-1,-1,-1\n")
    blocker = tmp_path / "file"
    blocker.write_text("")
    res = runner.invoke(app, ["eval", "--gt", str(tmp_path / "gt"), "--results", str(tmp_path / "res"),
                              "--metrics", "CLEAR,Identity", "--json", str(blocker / "e.json")])
    assert res.exit_code == 2
    assert "MOTA" not in res.output  # outputs are checked before anything is scored
    assert "is a file, not a folder" in res.output and "Traceback" not in res.output


def test_bench_real_json(tmp_path):
    if not (DATA / "mot15" / "TUD-Campus").is_dir():
        pytest.skip(f"real data not found at {DATA} (../shared/data)")
    _run(["bench", "real", "--data", str(DATA), "--datasets", "mot15", "--sequence", "TUD-Campus", "--peers", "none",
          "--trackers", "sort", "--json", str(tmp_path / "b.json")])
    doc = _valid(tmp_path / "b.json")
    assert doc["header"]["sequences"] == 1 and doc["header"]["frames"] > 0


def test_bench_ident_lengths_json_is_a_results_document(tmp_path):
    _run(["bench", "ident", "--setups", "m3n2", "--trackers", "kalman_ha", "--sequences", "1", "--frames", "60",
          "--lengths", "20,40", "--draws", "1", "--json", str(tmp_path / "t3.json")])
    doc = _valid(tmp_path / "t3.json")
    assert doc["header"]["kind"] == "bench ident" and doc["header"]["options"]["lengths"] == [20, 40]
    (row,) = doc["tables"]["ident_lengths"]
    assert row["dataset"] == "m3n2" and row["tracker"] == "kalman_ha"
    assert set(row["metrics"]) == {"success_rate_20_frames", "success_rate_40_frames", "success_rate",
                                   "localisation_error_m"}
    assert 0 <= row["metrics"]["success_rate"] <= 1


def test_bench_ident_lengths_json_on_recordings_with_a_human_row(tmp_path):
    from lookalike.bench.table3 import HUMAN, table3_results
    from lookalike.io.robot_sequences import write_robot_sequence
    from lookalike.sim import preset, simulate_robots

    write_robot_sequence(tmp_path / "m3n2-000001.jsonl", simulate_robots(preset("m3n2"), 50, 1))
    rows = [{"Setup": tmp_path.name, "Tracker": "kalman_ha", "20 frames (%)": 80.0, "Total, 50 frames (%)": 75.5,
             "Localisation error (m)": 0.2},
            {"Setup": tmp_path.name, "Tracker": HUMAN, "20 frames (%)": "—", "Total, 50 frames (%)": 90.0,
             "Localisation error (m)": "—"}]
    doc = table3_results(rows, [], 1, 50, 0, "ours", [20], 1, recordings=tmp_path, command="lookalike bench ident")
    data = _valid(doc.write(tmp_path / "t3.json"))
    assert data["header"]["seeds"] == [] and data["header"]["sequences"] == 1 and data["header"]["frames"] == 50
    assert [r["metrics"] for r in data["tables"]["ident_lengths"]] == [
        {"success_rate_20_frames": 0.8, "success_rate": 0.755, "localisation_error_m": 0.2}, {"success_rate": 0.9}]
