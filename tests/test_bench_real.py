"""``lookalike bench real``: boxtrack behaviour, the job backends (serial, processes, Ray) and the
leaderboard on real data (skipped without ../shared/data)."""

from __future__ import annotations

import importlib.util
import json
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from lookalike.bench.datasets import RealSequence, cut_sequence
from lookalike.bench.leaderboard import leaderboard
from lookalike.bench.peers import PEERS, peer_status, run_peer
from lookalike.bench.runner import (
    SEQUENCE_PARAMS,
    Entry,
    default_entries,
    job_pairs,
    run_jobs,
    score_rows,
    sequence_params,
    track_rows,
)
from lookalike.cli import app
from lookalike.io import MotTable
from lookalike.parallel import JobPool
from lookalike.trackers import make_tracker
from lookalike.trackers.offline.gap_fill import OfflineConfig, postprocess
from lookalike.types import Detections, Frame

DATA = Path(__file__).resolve().parents[1].parent / "shared" / "data"


def _synthetic(seed: int, n_frames: int = 40, n_targets: int = 3, name: str = "syn") -> RealSequence:
    """Targets walking in straight lines; detections = truth + 1 px noise, 10 % missed."""
    rng = np.random.default_rng(seed)
    start = rng.uniform(50, 400, size=(n_targets, 2))
    vel = rng.uniform(-3, 3, size=(n_targets, 2))
    gt_rows, det_xywh, det_score = [], [], []
    for k in range(n_frames):
        xy = start + vel * k
        boxes = np.hstack([xy, np.tile([40.0, 80.0], (n_targets, 1))])
        for i, b in enumerate(boxes):
            gt_rows.append([k + 1, i + 1, *b, 1, 1, 1, 1])
        seen = rng.random(n_targets) > 0.1
        det_xywh.append(boxes[seen] + rng.normal(0, 1.0, size=(seen.sum(), 4)) * [1, 1, 0, 0])
        det_score.append(rng.uniform(0.96, 1.0, size=seen.sum()))
    return RealSequence("synthetic", name, 10.0, n_frames, det_xywh, det_score,
                        gt=MotTable.from_rows(np.array(gt_rows)), n_targets=n_targets)


def _frame(k: int, xywh: list[list[float]], score: float = 0.99) -> Frame:
    boxes = np.array(xywh, dtype=float).reshape(-1, 4)
    return Frame(index=k, time=k / 10.0, detections=Detections(xywh=boxes, score=np.full(len(boxes), score)))


def test_boxtrack_reidentifies_a_target_after_a_gap() -> None:
    tracker = make_tracker("boxtrack")
    ids = []
    for k in range(20):
        boxes = [] if 8 <= k < 12 else [[100.0 + 4 * k, 100.0, 40.0, 80.0]]  # 0.4 s without detections
        ids += [t.track_id for t in tracker.update(_frame(k, boxes))]
    assert len(ids) >= 14 and set(ids) == {1}


def test_boxtrack_low_scores_never_start_tracks() -> None:
    # A low-scored box that flickers (somewhere else every frame) is clutter: the birth threshold is the
    # quantile 2 x (clutter share 1/3) of the scores seen, above 0.2. (A low-scored box that persists
    # like the others would start a track: a detector whose every box persists is trusted down to its
    # 10% quantile; tests/test_boxtrack_clutter.py.)
    tracker = make_tracker("boxtrack")
    ids = set()
    for k in range(10):
        boxes = np.array([[10.0 * k, 50.0, 40.0, 80.0], [300.0 + 150 * (k % 2), 200.0 * (k % 3), 40.0, 80.0],
                          [600.0, 50, 40, 80]])
        dets = Detections(xywh=boxes, score=np.array([0.99, 0.2, 0.98]))
        ids |= {(t.track_id, t.detection_index) for t in tracker.update(Frame(index=k, time=k / 10, detections=dets))}
    assert {d for _, d in ids} == {0, 2}
    # With raw thresholds only, a detector that never exceeds 0.5 starts nothing.
    tracker = make_tracker("boxtrack", clutter_factor=None)
    out = [tracker.update(_frame(k, [[10.0 * k, 50.0, 40.0, 80.0]], score=0.5)) for k in range(10)]
    assert all(not tracks for tracks in out)


def test_boxtrack_closed_set_never_exceeds_the_target_count() -> None:
    seq = _synthetic(3, n_frames=60, n_targets=4)
    rng = np.random.default_rng(0)
    tracker = make_tracker("boxtrack", max_targets=4)
    seen: set[int] = set()
    for k in range(seq.length):
        extra = rng.uniform(0, 500, size=(2, 4)) * [1, 1, 0.1, 0.2] + [0, 0, 20, 40]  # clutter
        boxes = np.vstack([seq.det_xywh[k], extra])
        dets = Detections(xywh=boxes, score=np.full(len(boxes), 0.99))
        seen |= {t.track_id for t in tracker.update(Frame(index=k, time=k / 10, detections=dets))}
    assert seen and max(seen) <= 4


def test_boxtrack_config_rejects_bad_values() -> None:
    with pytest.raises(ValueError, match="clutter_factor"):
        make_tracker("boxtrack", clutter_factor=-1.0)
    with pytest.raises(ValueError, match="max_targets"):
        make_tracker("boxtrack", max_targets=0)
    with pytest.raises(ValueError, match="low_score"):
        make_tracker("boxtrack", low_score=0.95, high_score=0.5)


def _square(x: int) -> int:
    return x * x


def map_jobs(fn, items, *, workers=1, backend="local"):
    """``[fn(x) for x in items]`` through a :class:`~lookalike.parallel.JobPool` of ``workers`` (in order)."""
    with JobPool(min(workers, max(len(items), 1)), backend) as pool:
        return pool.map(fn, items)


def test_map_jobs_processes_equal_serial_in_order() -> None:
    items = list(range(7))
    assert map_jobs(_square, items, workers=2) == map_jobs(_square, items) == [x * x for x in items]
    with pytest.raises(ValueError, match="backend"):
        map_jobs(_square, items, backend="dask")


def _tables(results: list, entries: list[Entry], seqs: list[RealSequence]) -> tuple:
    rows, combined, per_seq = leaderboard(entries, seqs, results)
    strip = [{k: v for k, v in r.items() if k != "Frames/s"} for r in rows]
    return strip, combined, per_seq


def test_leaderboard_is_the_same_with_processes() -> None:
    seqs = [_synthetic(1, name="a"), _synthetic(2, name="b")]
    entries = default_entries(["sort", "boxtrack"], [])
    serial = _tables(run_jobs(entries, seqs), entries, seqs)
    parallel = _tables(run_jobs(entries, seqs, workers=2), entries, seqs)
    assert serial == parallel
    rows = serial[0]
    assert {r["Tracker"] for r in rows} == {"sort", "boxtrack", "boxtrack-offline", "boxtrack-closed",
                                             "boxtrack-closed-offline"}
    assert sorted(r["Rank"] for r in rows) == [1, 2, 3, 4, 5]
    assert all(0 < r["IDF1"] <= 100 for r in rows)


def test_unknown_peer_is_reported_not_fatal() -> None:
    seq = _synthetic(4)
    with pytest.raises(ValueError, match="unknown peer"):
        track_rows(Entry("x", "no-such-peer", kind="peer"), seq)
    (result,) = run_jobs([Entry("x", "no-such-peer", kind="peer")], [seq])
    assert "unknown peer" in result["error"]


BOXMOT_TRACKERS = ("botsort", "bytetrack", "ocsort", "deepocsort", "hybridsort", "boosttrack", "occluboost", "sfsort")


def test_boxmot_peers_are_listed_and_skipped_with_a_reason_when_absent() -> None:
    names = [f"boxmot-{t}" for t in BOXMOT_TRACKERS]
    assert set(names) <= set(PEERS)
    status = peer_status(names)
    if importlib.util.find_spec("boxmot") is None:
        assert status == dict.fromkeys(names, "boxmot not installed")
    else:
        assert status == dict.fromkeys(names)


@pytest.mark.bench
@pytest.mark.parametrize("tracker", BOXMOT_TRACKERS)
def test_boxmot_peer_runs_on_boxes_alone(tracker: str) -> None:
    """Its default preset, no appearance model, no image content (``make bench-test`` runs it in .venv-bench)."""
    name = f"boxmot-{tracker}"
    why = peer_status([name])[name]
    if why is not None:
        pytest.skip(f"{name}: {why} (make bench-test installs it in .venv-bench)")
    seq = _synthetic(3, n_frames=60, n_targets=4)
    rows = run_peer(name, seq)
    assert rows.shape[1] == 10 and len(rows) > 0
    assert 1 <= rows[:, 0].min() and rows[:, 0].max() <= seq.length and (rows[:, 1] >= 1).all()
    assert score_rows(seq, rows)["MOTA"] > 0.7  # 4 straight walkers, 10 % missed: every preset follows them


def test_ray_backend_gives_the_local_tables() -> None:
    ray = pytest.importorskip("ray", reason="ray is not installed")
    seqs = [_synthetic(5, name="a"), _synthetic(6, name="b")]
    entries = default_entries(["sort", "boxtrack"], [])
    ray.init(num_cpus=2, include_dashboard=False, log_to_driver=False)
    try:
        remote = run_jobs(entries, seqs, backend="ray")
        squares = map_jobs(_square, [1, 2, 3], backend="ray")
    finally:
        ray.shutdown()
    assert squares == [1, 4, 9]
    assert _tables(remote, entries, seqs) == _tables(run_jobs(entries, seqs), entries, seqs)


def _need_data(sub: str) -> Path:
    path = DATA / sub
    if not path.is_dir():
        pytest.skip(f"real data not found at {path} (../shared/data)")
    return path


def test_bench_real_cli_on_tud_campus(tmp_path: Path) -> None:
    _need_data("mot15/TUD-Campus")
    out = tmp_path / "real.json"
    res = CliRunner().invoke(app, ["bench", "real", "--data", str(DATA), "--datasets", "mot15", "--sequence",
                                   "TUD-Campus", "--peers", "none", "--json", str(out), "--csv",
                                   str(tmp_path / "real.csv")])
    assert res.exit_code == 0, res.output
    tables = json.loads(out.read_text())["tables"]
    names = {r["tracker"] for r in tables["datasets"]}
    # no closed-set entry: MOT15 has no known target count
    assert names == {"sort", "boxtrack", "boxtrack-offline", "boxtrack (tuned on this data)"}
    sort_row = next(r for r in tables["datasets"] if r["tracker"] == "sort")
    assert sort_row["combined"] and sort_row["dataset"] == "mot15" and sort_row["sequence"] is None
    assert sort_row["metrics"]["mota"] == pytest.approx(0.627, abs=0.001)  # SORT's published behaviour on TUD-Campus
    assert {r["sequence"] for r in tables["sequences"]} == {"TUD-Campus"}
    assert all(r["dataset"] is None and r["combined"] for r in tables["ranking"])
    assert (tmp_path / "real.csv").read_text().startswith("Dataset,Tracker,HOTA")


def test_boxtrack_closed_set_beats_sort_on_the_pigs() -> None:
    _need_data("pigs")
    from lookalike.bench.datasets import load_boxes

    (pigs,) = load_boxes(DATA / "pigs", "pigs")
    entries = [Entry("sort", "sort"), Entry("boxtrack-closed", "boxtrack", closed_set=True)]
    rows, _, _ = leaderboard(entries, [pigs], run_jobs(entries, [pigs]))
    idf1 = {r["Tracker"]: r["IDF1"] for r in rows}
    assert idf1["boxtrack-closed"] > idf1["sort"] + 5


def test_bench_real_rejects_bad_options() -> None:
    runner = CliRunner()
    res = runner.invoke(app, ["bench", "real", "--backend", "spark", "--peers", "none"])
    assert res.exit_code != 0 and "backend" in res.output
    res = runner.invoke(app, ["bench", "real", "--trackers", "jpda", "--peers", "none"])
    assert res.exit_code != 0 and "box tracker" in res.output


def test_cut_sequence_splits_detections_and_truth_into_halves() -> None:
    seq = _synthetic(7, n_frames=41)
    first, second = cut_sequence(seq, "first"), cut_sequence(seq, "second")
    assert (first.length, second.length) == (20, 21) and cut_sequence(seq, "full") is seq
    assert first.name == "syn[first]" and second.name == "syn[second]"
    assert first.gt.frame.max() == 20 and second.gt.frame.min() == 1 and second.gt.frame.max() == 21
    assert len(first.gt.frame) + len(second.gt.frame) == len(seq.gt.frame)
    np.testing.assert_array_equal(second.det_xywh[0], seq.det_xywh[20])
    with pytest.raises(ValueError, match="part"):
        cut_sequence(seq, "middle")


def test_per_sequence_and_offline_entries() -> None:
    tuned = next(iter(SEQUENCE_PARAMS["mot15"]["boxtrack"]))
    seq = RealSequence("mot15", f"{tuned}[second]", 10.0, 0, [], [])
    # only the "tuned on this data" row gets the parameters chosen per sequence; the headline row has the defaults
    assert sequence_params(Entry("t", "boxtrack", tuned=True), seq) == SEQUENCE_PARAMS["mot15"]["boxtrack"][tuned]
    assert sequence_params(Entry("boxtrack", "boxtrack"), seq) == {}
    syn = _synthetic(8)
    entries = default_entries(["boxtrack"], [])

    def labels(s):
        return [e.label for e, _ in job_pairs(entries, [s])]

    # the synthetic dataset has no parameters chosen on it: no tuned row
    assert labels(syn) == ["boxtrack", "boxtrack-offline", "boxtrack-closed", "boxtrack-closed-offline"]
    assert labels(seq) == ["boxtrack", "boxtrack-offline", "boxtrack (tuned on this data)"]
    # an offline entry is the online result post-processed with the offline defaults
    pigs = RealSequence("pigs", "p", syn.frame_rate, syn.length, syn.det_xywh, syn.det_score, gt=syn.gt)
    online = track_rows(Entry("b", "boxtrack"), pigs)
    offline = track_rows(Entry("b", "boxtrack", offline=True), pigs)
    np.testing.assert_array_equal(offline,
                                  postprocess(online, pigs.frame_rate, OfflineConfig()))
    assert len(offline) > len(online)  # 10 % missed detections leave gaps to fill


def test_boxtrack_beats_sort_on_unseen_second_halves() -> None:
    """On the MOT15 second halves (never used to choose anything) boxtrack's defaults and the per-sequence
    choice beat lookalike's SORT on HOTA, IDF1 and MOTA; the offline pass on HOTA and IDF1 only (its
    interpolated gaps cost MOTA there); the per-sequence choice beats the defaults on MOTA only."""
    _need_data("mot15")
    from lookalike.bench.datasets import load_boxes

    seqs = [cut_sequence(s, "second") for s in load_boxes(DATA / "mot15", "mot15")]
    entries = default_entries(["sort", "boxtrack"], [])
    rows, _, _ = leaderboard(entries, seqs, run_jobs(entries, seqs))
    by = {r["Tracker"]: r for r in rows}
    for label, metrics in (("boxtrack", ("HOTA", "IDF1", "MOTA")), ("boxtrack-offline", ("HOTA", "IDF1")),
                           ("boxtrack (tuned on this data)", ("HOTA", "IDF1", "MOTA"))):
        for metric in metrics:
            assert by[label][metric] > by["sort"][metric], (label, metric)
    assert by["boxtrack (tuned on this data)"]["MOTA"] > by["boxtrack"]["MOTA"]


def test_synthesized_detections_follow_the_noise_model() -> None:
    from lookalike.bench.datasets import synthesize_detections

    n_frames, boxes = 200, []
    for k in range(1, n_frames + 1):
        boxes.append([k, 1, 100, 100, 50, 100, 1, 1, 1.0])  # a visible pedestrian
        boxes.append([k, 2, 400, 100, 50, 100, 1, 1, 0.1])  # hidden: never detected
        boxes.append([k, 3, 700, 100, 50, 100, 0, 1, 1.0])  # not considered: never detected
    gt = MotTable.from_rows(np.array(boxes, dtype=float))
    xywh, score = synthesize_detections(gt, n_frames, (1000, 500), np.random.default_rng(0))
    det, conf = np.vstack(xywh), np.concatenate(score)
    true = (np.abs(det[:, 0] - 100) < 30) & (np.abs(det[:, 1] - 100) < 30)
    assert 0.84 < true.sum() / n_frames < 0.96  # 10 % missed
    assert not np.any((np.abs(det[:, 0] - 400) < 5) & (np.abs(det[:, 1] - 100) < 5) & (np.abs(det[:, 2] - 50) < 5))
    assert abs(np.std(det[true, 0] - 100) - 0.05 * 50) < 0.6  # noise std is 5 % of the width
    assert conf[true].min() >= 0.6 and 50 < (~true).sum() < 150  # ~0.5 false boxes per frame
    again, _ = synthesize_detections(gt, n_frames, (1000, 500), np.random.default_rng(0))
    np.testing.assert_array_equal(np.vstack(again), det)
    with pytest.raises(ValueError, match="gt"):
        synthesize_detections(MotTable.from_rows(np.array(boxes, dtype=float)[:, :7]), 3, (10, 10),
                              np.random.default_rng(0))


def test_mot17_synth_loads_with_fixed_detections() -> None:
    root = _need_data("mot17/gt")
    from lookalike.bench.datasets import load_mot17_synth

    a, b = load_mot17_synth(root), load_mot17_synth(root)
    assert len(a) == 7 and all(s.benchmark == "MOT17" and s.dataset == "mot17-synth" for s in a)
    np.testing.assert_array_equal(a[0].det_xywh[10], b[0].det_xywh[10])
    assert a[0].length == len(a[0].det_xywh)


def test_mot17_synth2_is_the_same_truth_with_other_detections() -> None:
    root = _need_data("mot17")
    from lookalike.bench.datasets import load_datasets

    first = load_datasets(root.parent, ["mot17-synth"], sequences=["MOT17-02-FRCNN", "MOT17-02"])
    second = load_datasets(root.parent, ["mot17-synth2"], sequences=["MOT17-02-FRCNN", "MOT17-02"])
    assert len(first) == len(second) == 1 and second[0].dataset == "mot17-synth2"
    assert first[0].gt is not None and second[0].gt is not None
    np.testing.assert_array_equal(first[0].gt.xywh, second[0].gt.xywh)
    assert not np.array_equal(first[0].det_score[10], second[0].det_score[10])


def test_a_selection_that_matches_no_sequence_names_the_known_ones() -> None:
    root = _need_data("mot15")
    from lookalike.bench.datasets import load_datasets

    with pytest.raises(ValueError, match=r"no sequence selected: 'TUD-Campos' not in mot15; known: .*TUD-Campus"):
        load_datasets(root.parent, ["mot15"], sequences=["TUD-Campos"])
    assert [s.name for s in load_datasets(root.parent, ["mot15"], sequences=["TUD-Campus", "TUD-Campos"])] == \
        ["TUD-Campus"]
