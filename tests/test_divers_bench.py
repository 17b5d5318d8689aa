"""``lookalike bench divers``: table layout, ALL rows, outputs (on two shortened scenarios)."""

from __future__ import annotations

import json

import pytest

pytest.importorskip("lookalike.cli.bench", reason="the bench sub-app (lookalike.cli.bench) is not there yet")

from typer.testing import CliRunner

from lookalike.bench.divers import COLUMNS, bar_chart, diver_table
from lookalike.cli import app


def test_table_rows_and_all_row(tmp_path) -> None:
    rows = diver_table(["ocean_pair_clear", "pool_pair"], frames=60)
    assert [r["Tracker"] for r in rows[:3]] == ["sort", "deepsort", "diversort"]
    assert len(rows) == 9 and all(set(r) == set(COLUMNS) for r in rows)
    assert [r["Scenario"] for r in rows[-3:]] == ["ALL"] * 3
    for r in rows:
        assert 0 <= r["IDF1"] <= 100 and 0 < r["DR"] <= 100 and r["IDSW"] >= 0
    png = bar_chart(rows, tmp_path / "idf1.png")
    assert png.stat().st_size > 1000


def test_command_writes_json_csv_png(tmp_path) -> None:
    out = CliRunner().invoke(app, ["bench", "divers", "--scenario", "pool_pair", "--frames", "40",
                                   "--json", str(tmp_path / "t.json"), "--csv", str(tmp_path / "t.csv"),
                                   "--png", str(tmp_path / "f.png")])
    assert out.exit_code == 0, out.output
    rows = json.loads((tmp_path / "t.json").read_text())
    assert {r["Tracker"] for r in rows} == {"sort", "deepsort", "diversort"}
    assert (tmp_path / "t.csv").read_text().splitlines()[0].split(",") == list(COLUMNS)
    assert (tmp_path / "f.png").exists()
    bad = CliRunner().invoke(app, ["bench", "divers", "--scenario", "atlantis"])
    assert bad.exit_code != 0 and "unknown diver scenario" in bad.output
