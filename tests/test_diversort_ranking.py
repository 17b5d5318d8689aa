"""The paper's ranking on rendered divers: diver SORT > deep SORT style > SORT on pooled IDF1."""

from __future__ import annotations

import dataclasses

from lookalike.eval.api import combine, evaluate_sequence
from lookalike.io.motchallenge import MotTable
from lookalike.sim.divers import SCENARIOS
from lookalike.sim.divers_run import fit_diver_features, prepare_features, run_tracker


def test_diversort_beats_deepsort_beats_sort_on_identical_detections() -> None:
    extractor = fit_diver_features(every=10)
    scores: dict[str, list[dict[str, float]]] = {"sort": [], "deepsort": [], "diversort": []}
    for sc in SCENARIOS[::2]:  # four scenarios, shortened
        prepared = prepare_features(dataclasses.replace(sc, frames=150), {"": extractor})[""]
        gt = MotTable.from_rows(prepared.gt)
        for name, per_scenario in scores.items():
            rows, _ = run_tracker(name, prepared.frames)
            per_scenario.append(evaluate_sequence(gt, MotTable.from_rows(rows), metrics=["Identity"], num_frames=150))
    idf1 = {name: combine(s)["IDF1"] for name, s in scores.items()}
    assert idf1["diversort"] > idf1["deepsort"] + 0.1
    assert idf1["deepsort"] > idf1["sort"]


def test_merges_are_reported_with_source_and_target() -> None:
    extractor = fit_diver_features(every=10)
    prepared = prepare_features(dataclasses.replace(SCENARIOS[3], frames=300), {"": extractor})[""]
    rows, tracker = run_tracker("diversort", prepared.frames)
    assert tracker.merges, "this scenario has returning divers that should be merged back"
    reported = set(rows[:, 1].astype(int))
    for merge in tracker.merges:
        assert merge.source_id != merge.target_id and merge.target_id in reported
        # from the merge frame on, the source id is never reported again
        later = rows[rows[:, 0] > merge.frame_index + 1]
        assert merge.source_id not in set(later[:, 1].astype(int))
