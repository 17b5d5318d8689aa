"""Ranking checks on real data (``pytest -m bench``): ``bench real`` on MOT15 and the pigs compared
with a stored baseline (tests/data/bench_real_baseline.json) within a tolerance, so that a change is
judged by behaviour rather than one run's figures. Skipped without ../shared/data."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from lookalike.bench.datasets import load_datasets
from lookalike.bench.leaderboard import leaderboard
from lookalike.bench.runner import default_entries, run_jobs

DATA = Path(__file__).resolve().parents[1].parent / "shared" / "data"
BASELINE = Path(__file__).parent / "data" / "bench_real_baseline.json"
TOLERANCE = 0.5  # percentage points of HOTA, IDF1, MOTA
METRICS = ("HOTA", "IDF1", "MOTA")

pytestmark = [pytest.mark.bench,
              pytest.mark.skipif(not (DATA / "mot15").is_dir() or not (DATA / "pigs").is_dir(),
                                 reason="../shared/data/mot15 and pigs are absent")]


@pytest.fixture(scope="module")
def tables() -> tuple[list[dict], list[dict]]:
    seqs = load_datasets(DATA, ["mot15", "pigs"])
    entries = default_entries(["sort", "boxtrack"], [])
    rows, combined, _ = leaderboard(entries, seqs, run_jobs(entries, seqs, workers=2))
    return rows, combined


def _baseline() -> dict:
    return json.loads(BASELINE.read_text())


def test_metrics_stay_within_tolerance_of_the_baseline(tables):
    rows, _ = tables
    now = {(r["Dataset"], r["Tracker"]): r for r in rows}
    for ref in _baseline()["datasets"]:
        got = now[(ref["Dataset"], ref["Tracker"])]
        for m in METRICS:
            assert abs(got[m] - ref[m]) <= TOLERANCE, (ref["Dataset"], ref["Tracker"], m, got[m], ref[m])


def test_ranks_are_those_of_the_baseline(tables):
    rows, combined = tables
    for dataset in ("mot15", "pigs"):
        ref = [r["Tracker"] for r in _baseline()["datasets"] if r["Dataset"] == dataset]
        assert [r["Tracker"] for r in rows if r["Dataset"] == dataset] == ref
    assert [r["Tracker"] for r in combined] == [r["Tracker"] for r in _baseline()["combined"]]


def test_every_boxtrack_entry_leads_sort(tables):
    rows, _ = tables
    for dataset in ("mot15", "pigs"):
        sort = next(r for r in rows if r["Dataset"] == dataset and r["Tracker"] == "sort")
        for r in (r for r in rows if r["Dataset"] == dataset and r["Tracker"].startswith("boxtrack")):
            assert r["HOTA"] > sort["HOTA"] and r["IDF1"] > sort["IDF1"], (dataset, r["Tracker"])
