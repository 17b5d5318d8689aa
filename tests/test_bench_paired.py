"""Paired comparison over sequences (lookalike.bench.paired) and the difference tables of
``bench ident`` and ``bench recovery``."""

from __future__ import annotations

import csv
import json
import math
import warnings

import numpy as np
import pytest
from typer.testing import CliRunner

from lookalike.bench.experiments import experiment_results, recovery_differences
from lookalike.bench.ident import IDENT_COLUMNS, ident_differences, ident_runs
from lookalike.bench.paired import NEVER, ONE_SEQUENCE, interval_text, mean_difference, rate_difference
from lookalike.cli import app
from lookalike.io.results import validate

pytest.importorskip("jsonschema", reason="jsonschema is in the test extra")
runner = CliRunner()
TINY = ["--setups", "m3n2", "--sequences", "2", "--frames", "30"]


def _counts(rate: float, rng: np.random.Generator, n: int = 10) -> tuple[np.ndarray, np.ndarray]:
    detections = rng.integers(200, 400, n)
    return rng.binomial(detections, rate), detections


def test_interval_contains_the_point_difference():
    rng = np.random.default_rng(1)
    a, detections = _counts(0.9, rng)
    b = rng.binomial(detections, 0.88)
    for result in (rate_difference(a, b, detections), mean_difference(a / detections, b / detections)):
        assert result.low <= result.difference <= result.high
        assert result.n_sequences == 10 and result.note == ""
    pooled = 100 * (a.sum() - b.sum()) / detections.sum()
    assert rate_difference(a, b, detections).difference == pytest.approx(pooled)


def test_identical_figures_give_zero_without_warnings():
    a, detections = _counts(0.9, np.random.default_rng(2))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        rate = rate_difference(a, a, detections)
        seconds = mean_difference([1.0, 2.0, 0.5], [1.0, 2.0, 0.5])
    for result in (rate, seconds):
        assert result.difference == 0 and result.low == 0 and result.high == 0 and not result.excludes_zero


def test_a_large_advantage_excludes_zero_either_way():
    rng = np.random.default_rng(3)
    b, detections = _counts(0.7, rng)
    a = rng.binomial(detections, 0.95)
    better, worse = rate_difference(a, b, detections), rate_difference(b, a, detections)
    assert better.low > 0 and better.excludes_zero
    assert worse.high < 0 and worse.excludes_zero
    assert better.difference == pytest.approx(-worse.difference)


def test_a_small_difference_against_a_wide_spread_does_not():
    rng = np.random.default_rng(4)
    b, detections = _counts(0.9, rng)
    a = np.minimum(detections, b + rng.integers(-40, 41, b.size))  # ~ +-10 points a sequence, ~0 on average
    result = rate_difference(a, b, detections)
    assert result.low < 0 < result.high and not result.excludes_zero


def test_the_interval_is_reproducible():
    a, detections = _counts(0.9, np.random.default_rng(5))
    b = np.random.default_rng(6).binomial(detections, 0.85)
    assert rate_difference(a, b, detections) == rate_difference(a, b, detections)


def test_one_sequence_and_never_recovering_give_no_interval():
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        one = rate_difference([90], [80], [100])
        never = mean_difference([1.0, math.inf, 2.0], [1.5, 1.0, 2.0])
        both_never = mean_difference([math.inf, 1.0], [math.inf, 2.0])
    assert one.difference == pytest.approx(10.0) and math.isnan(one.low) and math.isnan(one.high)
    assert one.note == ONE_SEQUENCE and not one.excludes_zero
    assert never.difference == math.inf and never.note == NEVER and interval_text(never) == "never"
    assert math.isnan(both_never.difference) and both_never.note == NEVER
    with pytest.raises(ValueError):
        rate_difference([1, 2], [1], [3, 3])


def test_recovery_differences_and_their_json():
    seconds = {("m3n2", "kalman_ha2"): [1.0, 1.2, 0.9], ("m3n2", "jpda"): [0.5, 0.7, 0.4],
               ("m3n2", "lstm"): [0.3, math.inf, 0.2]}
    diffs = recovery_differences(seconds, ["m3n2"], ["kalman_ha2", "jpda", "lstm"])
    assert [(d.tracker, d.baseline) for d in diffs] == [("jpda", "kalman_ha2"), ("lstm", "kalman_ha2")]
    assert diffs[0].result.difference == pytest.approx(-0.5) and diffs[0].result.high < 0
    assert diffs[1].result.note == NEVER
    assert recovery_differences(seconds, ["m3n2"], ["jpda"]) == []
    assert recovery_differences({k: v[:1] for k, v in seconds.items()}, ["m3n2"], ["kalman_ha2", "jpda"]) == []
    doc = experiment_results("recovery", [], ["m3n2"], 3, 900, differences=diffs).to_dict()
    validate(doc)
    rows = doc["tables"]["recovery_difference"]
    assert rows[0]["metrics"]["ci_high_s"] < 0 and rows[0]["info"]["baseline"] == "kalman_ha2"
    assert rows[1]["metrics"]["ci_low_s"] is None and rows[1]["info"]["note"] == NEVER


def test_per_sequence_counts_pool_to_the_printed_rate():
    rows, counts = ident_runs(["m3n2"], ["kalman_ha", "jpda"], sequences=2, frames=30)
    for r in rows:
        per_seq = counts[("m3n2", r["Tracker"])]
        assert len(per_seq) == 2 and sum(n for _, n in per_seq) == r["Detections"]
        assert round(100 * sum(c for c, _ in per_seq) / r["Detections"], 2) == r["Success rate (%)"]
    diffs = ident_differences(counts, ["m3n2"], ["kalman_ha", "jpda"])
    assert [(d.tracker, d.baseline, d.result.n_sequences) for d in diffs] == [("jpda", "kalman_ha", 2)]
    assert ident_differences(counts, ["m3n2"], ["kalman_ha"]) == []


def test_identifiers_that_did_not_run_are_skipped():
    counts = {("m3n2", "kalman_ha"): [(80, 100), (85, 100)], ("m3n2", "jpda"): [(90, 100), (92, 100)]}
    # lstm-paper: not trained for the set-up, so ident_runs has no counts for it
    assert [d.tracker for d in ident_differences(counts, ["m3n2"], ["kalman_ha", "lstm-paper", "jpda"])] == ["jpda"]
    assert ident_differences(counts, ["m3n2"], ["lstm-paper", "kalman_ha", "jpda"]) == []


def test_bench_ident_prints_and_writes_the_difference_table(tmp_path):
    res = runner.invoke(app, ["bench", "ident", *TINY, "--trackers", "kalman_ha,jpda",
                              "--json", str(tmp_path / "t.json"), "--csv", str(tmp_path / "t.csv")])
    assert res.exit_code == 0, res.output
    assert "Difference from kalman_ha" in res.output and "95% CI" in res.output
    doc = json.loads((tmp_path / "t.json").read_text())
    validate(doc)
    assert [r["tracker"] for r in doc["tables"]["ident"]] == ["kalman_ha", "jpda"]
    (row,) = doc["tables"]["ident_difference"]
    assert row["tracker"] == "jpda" and row["info"] == {"baseline": "kalman_ha", "figure": "success_rate"}
    m = row["metrics"]
    assert m["sequences"] == 2 and m["ci_low"] <= m["difference"] <= m["ci_high"]
    rates = {r["tracker"]: r["metrics"]["success_rate"] for r in doc["tables"]["ident"]}
    assert m["difference"] == pytest.approx(rates["jpda"] - rates["kalman_ha"], abs=1e-4)
    with open(tmp_path / "t.csv", newline="") as f:
        csv_rows = list(csv.DictReader(f))
    assert len(csv_rows) == 2 and list(csv_rows[0]) == list(IDENT_COLUMNS)


def test_bench_ident_without_a_comparison_prints_no_difference_table(tmp_path):
    one = runner.invoke(app, ["bench", "ident", *TINY, "--trackers", "jpda", "--json", str(tmp_path / "a.json")])
    single = runner.invoke(app, ["bench", "ident", "--setups", "m3n2", "--sequences", "1", "--frames", "30",
                                 "--trackers", "kalman_ha,jpda", "--json", str(tmp_path / "b.json")])
    for res, name in ((one, "a.json"), (single, "b.json")):
        assert res.exit_code == 0, res.output
        assert "Difference from" not in res.output
        doc = json.loads((tmp_path / name).read_text())
        validate(doc)
        assert set(doc["tables"]) == {"ident"}


def test_bench_recovery_prints_the_difference_table(tmp_path):
    res = runner.invoke(app, ["bench", "recovery", "--setups", "m3n2", "--trackers", "kalman_ha2,jpda",
                              "--sequences", "2", "--frames", "450", "--swap-at-s", "3", "--swap-s", "5",
                              "--json", str(tmp_path / "r.json")])
    assert res.exit_code == 0, res.output
    assert "difference from" in res.output
    doc = json.loads((tmp_path / "r.json").read_text())
    validate(doc)
    assert [r["tracker"] for r in doc["tables"]["recovery_difference"]] == ["jpda"]
