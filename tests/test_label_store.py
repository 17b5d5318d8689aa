"""Label store, scoring, exports and starting labels of the labelling page."""

from __future__ import annotations

import json

import numpy as np
import pytest

from lookalike.io import read_mot
from lookalike.io.robot_sequences import read_robot_sequence, write_robot_sequence
from lookalike.sim import preset, simulate_robots
from lookalike.viz.label import (
    UNSET,
    export_mot,
    export_truth,
    label_path_for,
    load_labels,
    open_label_app,
    score_labels,
)


@pytest.fixture()
def seq_path(tmp_path):
    return write_robot_sequence(tmp_path / "m5n3-000007.jsonl", simulate_robots(preset("m5n3"), 40, 7))


def test_store_saves_every_change_atomically_and_reloads(seq_path):
    app = open_label_app(seq_path)
    store = app.store
    assert store.path == label_path_for(seq_path) == seq_path.with_name("m5n3-000007.labels.json")
    k = next(i for i, n in enumerate(store.counts) if n >= 2)
    store.set_label(k, 0, 2)
    store.set_label(k, 1, -1)
    on_disk = json.loads(store.path.read_text())
    assert on_disk["labels"][k][:2] == [2, -1]
    assert [p.name for p in seq_path.parent.iterdir() if p.name.endswith(".tmp")] == []
    again = open_label_app(seq_path).store
    assert again.snapshot() == store.snapshot()
    assert again.snapshot()[k][:2] == [2, -1]


@pytest.mark.parametrize("args", [(0, 0, 3), (0, 0, -3), (10_000, 0, 0), (0, 99, 0), (0, 0, 1.5), (0, 0, True)])
def test_store_rejects_bad_labels(seq_path, args):
    store = open_label_app(seq_path).store
    if store.counts[0] == 0 and args[1] == 0 and args[0] == 0:
        pytest.skip("frame 0 has no detections in this seed")
    with pytest.raises(ValueError):
        store.set_label(*args)


def test_store_refuses_a_label_file_of_another_sequence(seq_path, tmp_path):
    open_label_app(seq_path)
    other = write_robot_sequence(tmp_path / "other.jsonl", simulate_robots(preset("m5n3"), 40, 8))
    label_path_for(seq_path).replace(label_path_for(other))
    with pytest.raises(ValueError, match="labels of"):
        open_label_app(other)


def test_score_counts_unset_as_wrong_and_stops_at_the_last_touched_frame():
    truth = [np.array([0, 1]), np.array([1, -1]), np.array([0])]
    labels = [[0, 1], [1, UNSET], [UNSET]]
    r = score_labels(labels, truth, n_agents=2)
    assert r["frames_scored"] == 2 and r["detections_scored"] == 4
    assert r["correct"] == 3 and r["unset"] == 1
    assert r["success_rate"] == pytest.approx(0.75)
    assert r["success_rate_all"] == pytest.approx(3 / 5)
    empty = score_labels([[UNSET], [UNSET]], [np.array([0]), np.array([1])], 2)
    assert empty["frames_scored"] == 0 and empty["success_rate"] is None


def test_truth_labels_score_perfectly_and_survive_both_exports(seq_path):
    seq = read_robot_sequence(seq_path)
    truth = [t.tolist() for t in seq.true_labels()]
    assert score_labels(truth, seq.true_labels(), 3)["success_rate"] == 1.0
    labels = [list(r) for r in truth]
    k = next(i for i, r in enumerate(labels) if r)
    labels[k][0] = UNSET
    path, unset = export_truth(seq, labels, seq_path.with_name("out.jsonl"))
    assert unset == 1
    back = read_robot_sequence(path)
    assert back.true_labels()[k][0] == -1
    assert np.array_equal(back.arrays.det_position, seq.arrays.det_position)
    mot, rows = export_mot(seq, truth, seq_path.with_name("out.txt"))
    assert rows == int((seq.arrays.det_label[seq.arrays.det_valid] >= 0).sum())
    table = read_mot(mot)
    assert table.track_id.min() >= 1 and table.track_id.max() <= 3
    assert load_labels(mot, seq) == truth
    assert load_labels(seq_path, seq) == truth
    labels_file = open_label_app(seq_path, initial=truth, source="t").store.path
    assert load_labels(labels_file, seq) == truth


def test_load_labels_rejects_files_of_other_detections(seq_path, tmp_path):
    seq = read_robot_sequence(seq_path)
    other = write_robot_sequence(tmp_path / "other.jsonl", simulate_robots(preset("m5n3"), 40, 8))
    with pytest.raises(ValueError, match="not this sequence"):
        load_labels(other, seq)
    bad = tmp_path / "bad.json"
    bad.write_text("{not json")
    with pytest.raises(ValueError, match="not JSON"):
        load_labels(bad, seq)
    csv = tmp_path / "x.csv"
    csv.write_text("1,2\n")
    with pytest.raises(ValueError, match="expected"):
        load_labels(csv, seq)
    with pytest.raises(ValueError, match="no such file"):
        load_labels(tmp_path / "missing.json", seq)


def test_benchmark_session_is_timed_scored_and_locked(seq_path):
    app = open_label_app(seq_path, benchmark=True)
    store = app.store
    store.start_benchmark(now=100.0)
    store.start_benchmark(now=150.0)  # a second start keeps the first
    truth = app.truth
    for k in range(5):
        for j, t in enumerate(truth[k]):
            store.set_label(k, j, int(t) if j else -1)
    result = store.finish_benchmark(truth, now=160.0)
    assert result["duration_s"] == pytest.approx(60.0)
    expected = score_labels(store.snapshot(), truth, 3)
    assert result["success_rate"] == pytest.approx(expected["success_rate"])
    assert result["frames_scored"] == 5
    with pytest.raises(ValueError, match="locked"):
        store.set_label(0, 0, 0) if store.counts[0] else store.set_label(1, 0, 0)
    reopened = open_label_app(seq_path, benchmark=True).store
    assert reopened.benchmark["duration_s"] == pytest.approx(60.0)


def test_benchmark_refuses_starting_labels(seq_path):
    seq = read_robot_sequence(seq_path)
    with pytest.raises(ValueError, match="benchmark"):
        open_label_app(seq_path, initial=[t.tolist() for t in seq.true_labels()], benchmark=True)
    open_label_app(seq_path, initial=[t.tolist() for t in seq.true_labels()], source="tracker x")
    with pytest.raises(ValueError, match="--fresh"):
        open_label_app(seq_path, benchmark=True)
    app = open_label_app(seq_path, benchmark=True, fresh=True)
    assert app.store.source == "empty"
    assert label_path_for(seq_path).with_name("m5n3-000007.labels.json.bak").exists()
