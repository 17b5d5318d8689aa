"""``lookalike bench divers``: table layout, ALL rows, outputs (on two shortened scenarios)."""

from __future__ import annotations

import json

import pytest

pytest.importorskip("lookalike.cli.bench", reason="the bench sub-app (lookalike.cli.bench) is not there yet")

from typer.testing import CliRunner

from lookalike.bench.divers import COLUMNS, ENTRIES, TRACKERS, bar_chart, diver_table, entries, pearson
from lookalike.cli import app
from lookalike.sim.divers import SCENARIOS, simulate_divers
from lookalike.sim.divers_paper import PAPER_DETECTORS, redraw, with_detections


def test_table_rows_and_all_row(tmp_path) -> None:
    rows = diver_table(["ocean_pair_clear", "pool_pair"], frames=60)
    assert [r["Tracker"] for r in rows[:5]] == list(TRACKERS)
    assert TRACKERS[1] == "deepsort/learned" and TRACKERS[3] == "diversort/handcrafted"
    assert len(rows) == 15 and all(set(r) == set(COLUMNS) for r in rows)
    assert [r["Scenario"] for r in rows[-5:]] == ["ALL"] * 5
    for r in rows:
        assert 0 <= r["IDF1"] <= 100 and 0 < r["DR"] <= 100 and r["IDSW"] >= 0
    png = bar_chart(rows, tmp_path / "idf1.png")
    assert png.stat().st_size > 1000


def test_pearson_per_tracker_leaves_out_all_rows() -> None:
    rows = [{"Scenario": s, "Tracker": "t", "DP": dp, "IDP": idp}
            for s, dp, idp in (("a", 30, 20), ("b", 50, 41), ("c", 80, 70), ("ALL", 0, 100))]
    r, p = pearson(rows)["t"]
    assert r > 0.99 and 0 <= p < 0.1
    assert all(v != v for v in pearson(rows[:2])["t"])  # too few scenarios: nan


def test_paper_detections_are_harder_and_seeds_redraw() -> None:
    assert set(PAPER_DETECTORS) == {sc.name for sc in SCENARIOS}
    sc = SCENARIOS[0]
    hard = with_detections(sc, "paper")
    assert hard.detector.recall < sc.detector.recall and hard.seed == sc.seed
    assert redraw(sc, 0) is sc and redraw(sc, 2).seed != sc.seed
    a, b = simulate_divers(redraw(hard, 1)), simulate_divers(hard)
    assert a.gt.shape != b.gt.shape or not (a.gt == b.gt).all()
    with pytest.raises(ValueError, match="detections"):
        with_detections(sc, "perfect")


def test_command_writes_results_csv_png(tmp_path) -> None:
    out = CliRunner().invoke(app, ["bench", "divers", "--scenario", "pool_pair", "--frames", "40",
                                   "--tracker", "sort", "--tracker", "diversort/handcrafted", "--detections", "both",
                                   "--seed", "1", "--json", str(tmp_path / "t.json"), "--csv", str(tmp_path / "t.csv"),
                                   "--png", str(tmp_path / "f.png")])
    assert out.exit_code == 0, out.output
    assert "Pearson" in out.output and "detections: paper" in out.output
    doc = json.loads((tmp_path / "t.json").read_text())
    assert doc["schema"] == "lookalike-results/1"
    jsonschema = pytest.importorskip("jsonschema", reason="jsonschema is in the test extra")
    from lookalike.io.results import schema

    jsonschema.validate(doc, schema())
    rows = doc["tables"]["divers"]
    assert {r["tracker"] for r in rows} == {"sort", "diversort/handcrafted"}
    assert {r["dataset"] for r in rows} == {"divers-sim", "divers-paper"}
    assert [r["combined"] for r in rows if r["sequence"] is None] == [True] * 4
    assert all(0 <= r["metrics"]["idf1"] <= 1 for r in rows)
    assert (tmp_path / "t.csv").read_text().splitlines()[0].split(",") == ["Detections", *COLUMNS]
    assert (tmp_path / "f.png").exists()
    bad = CliRunner().invoke(app, ["bench", "divers", "--scenario", "atlantis"])
    assert bad.exit_code != 0 and "unknown diver scenario" in bad.output
    bad = CliRunner().invoke(app, ["bench", "divers", "--scenario", "pool_pair", "--tracker", "magic"])
    assert bad.exit_code == 2 and "magic" in bad.output


def test_feature_sets_by_name_and_onnx_file(tmp_path) -> None:
    import shutil

    from lookalike.vision.appearance_onnx import LEARNED_MODEL

    assert entries() == ENTRIES
    assert [e[0] for e in entries(("handcrafted",))] == ["sort", "deepsort/handcrafted", "diversort/handcrafted"]
    model = shutil.copy(LEARNED_MODEL, tmp_path / "reid2.onnx")
    shutil.copy(LEARNED_MODEL.with_suffix(".json"), tmp_path / "reid2.json")
    out = CliRunner().invoke(app, ["bench", "divers", "--scenario", "pool_pair", "--frames", "30",
                                   "--features", str(model), "--tracker", "diversort/reid2"])
    assert out.exit_code == 0, out.output
    assert "diversort/reid2" in out.output


def test_matched_thresholds_of_a_model_with_tiny_distances_are_not_zero(monkeypatch) -> None:
    """An embedding whose same-diver distances are all under 1e-4 gets thresholds a tracker accepts."""
    import numpy as np

    from lookalike.sim import divers_run
    from lookalike.trackers import make_tracker

    monkeypatch.setattr(divers_run, "_reference_distances", lambda: np.linspace(0.0, 0.5, 101))
    monkeypatch.setattr(divers_run, "_distances_of", lambda extractor: np.linspace(0.0, 5e-5, 101))
    extractor = object()  # (any extractor other than the hand-crafted one, without stored thresholds)
    for tracker in ("deepsort", "diversort"):
        found = divers_run.matched_thresholds(extractor, tracker)  # type: ignore[arg-type]
        assert found and all(0 < v < 1e-4 for v in found.values()), found
        make_tracker(tracker, **found)


def test_cli_scenarios_and_trackers_take_comma_separated_lists_as_the_other_benches(tmp_path):
    runner = CliRunner()
    out = tmp_path / "d.json"
    r = runner.invoke(app, ["bench", "divers", "--scenarios", "pool_pair,ocean_pair_clear", "--frames", "10",
                            "--trackers", "sort", "--json", str(out)])
    assert r.exit_code == 0, r.output
    rows = json.loads(out.read_text())["tables"]["divers"]
    assert {(r["sequence"], r["tracker"]) for r in rows if not r["combined"]} == {
        ("pool_pair", "sort"), ("ocean_pair_clear", "sort")}
    r = runner.invoke(app, ["bench", "divers", "--tracker", ",", "--frames", "10"])
    assert r.exit_code == 2 and "--trackers: no name given" in r.output, r.output


def test_cli_frames_help_says_what_the_option_does_beyond_300_frames():
    r = CliRunner().invoke(app, ["bench", "divers", "--help"], env={"COLUMNS": "200"})
    assert {sc.frames for sc in SCENARIOS} == {300}
    assert "each scenario's 300; fewer cuts it short, more draws it longer" in " ".join(r.output.split())


def test_cli_png_that_cannot_be_written_is_one_line(tmp_path, monkeypatch):
    import errno

    import lookalike.cli.bench_divers as cli_divers

    def disk_full(rows, path):
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(cli_divers, "bar_chart", disk_full)
    png = tmp_path / "idf1.png"
    r = CliRunner().invoke(app, ["bench", "divers", "--scenario", "pool_pair", "--frames", "10", "--trackers", "sort",
                                 "--png", str(png), "--json", str(tmp_path / "d.json")])
    assert r.exit_code == 2 and "Traceback" not in r.output, r.output
    assert r.output.strip().splitlines()[-1] == f"error: --png: cannot write {png}: No space left on device"
    assert (tmp_path / "d.json").is_file()
