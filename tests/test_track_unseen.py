"""The commands a user runs on unseen data: ``track --params``, ``--targets N --offline``, ``--points``,
blob settings estimated from the video (printed, ``--blob`` wins, cached), ``eval --points``, and the
bench's ``--params`` row and closed-set offline entry."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from lookalike.bench.datasets import RealSequence
from lookalike.bench.runner import Entry, default_entries, job_pairs, params_entry, track_rows
from lookalike.cli import app
from lookalike.io import read_mot, write_mot
from lookalike.io.video_frames import read_frames
from lookalike.pipeline.blob_detections import (
    auto_blob_config,
    cached_blob_detections,
    detection_cache_key,
    load_blob_detections,
)
from lookalike.tune.params_file import save_params

runner = CliRunner()


@pytest.fixture(autouse=True)
def _private_cache(tmp_path, monkeypatch):
    monkeypatch.setenv("LOOKALIKE_CACHE", str(tmp_path / "cache"))


def _crossing_rows(frames: int = 60, gap: tuple[int, int] = (27, 33)) -> np.ndarray:
    """Two targets crossing in an X, both undetected for the frames in ``gap`` (1-based, inclusive)."""
    rows = []
    for f in range(1, frames + 1):
        if gap[0] <= f <= gap[1]:
            continue
        for x0, vy in ((10.0, 2.0), (10.0, -2.0)):
            x, y = x0 + 3.0 * f, 100.0 + vy * (f - frames / 2)
            rows.append([f, -1, x - 5, y - 5, 10, 10, 0.99, -1, -1, -1])
    return np.array(rows)


def _write_det(tmp_path: Path, rows: np.ndarray) -> Path:
    return write_mot(tmp_path / "det.txt", rows)


def _one_line_error(result) -> str:
    return " ".join(result.output.split())


def test_params_file_is_the_tracker_and_set_overrides_it(tmp_path):
    det = _write_det(tmp_path, _crossing_rows())
    params = save_params(tmp_path / "p.json", "boxtrack", {"n_init": 1, "max_age_s": 0.1}, chosen_on=["x/y"],
                         criterion="idf1", trials=1)
    outs = {}
    for name, extra in {"file": ["--params", str(params)], "set": ["--set", "n_init=1", "--set", "max_age_s=0.1"],
                        "default": [], "file+set": ["--params", str(params), "--set", "n_init=3"]}.items():
        out = tmp_path / f"{name}.txt"
        r = runner.invoke(app, ["track", str(det), "-t", "boxtrack", *extra, "-o", str(out)])
        assert r.exit_code == 0, r.output
        outs[name] = np.loadtxt(out, delimiter=",")
    np.testing.assert_array_equal(outs["file"], outs["set"])
    assert not np.array_equal(outs["file"], outs["default"])  # the file's values are used
    r = runner.invoke(app, ["track", str(det), "-t", "boxtrack", "--set", "n_init=3", "--set", "max_age_s=0.1",
                            "-o", str(tmp_path / "both.txt")])
    assert r.exit_code == 0, r.output
    np.testing.assert_array_equal(outs["file+set"], np.loadtxt(tmp_path / "both.txt", delimiter=","))
    r = runner.invoke(app, ["track", str(det), "-t", "sort", "--params", str(params), "-o", str(tmp_path / "s.txt")])
    assert r.exit_code != 0 and "not 'sort'" in _one_line_error(r)


def test_offline_needs_targets_in_one_line(tmp_path):
    det = _write_det(tmp_path, _crossing_rows())
    r = runner.invoke(app, ["track", str(det), "-t", "boxtrack", "--offline", "-o", str(tmp_path / "o.txt")])
    assert r.exit_code != 0 and "--offline: needs --targets N" in _one_line_error(r)
    assert "Traceback" not in r.output


def test_offline_writes_the_closed_set_of_the_whole_sequence(tmp_path):
    """``--targets N --offline`` writes exactly :func:`track_closed_set` of the file's detections (ids 1..N)."""
    from lookalike.trackers.offline.closed_set import track_closed_set
    from lookalike.trackers.offline.confidence import assignment_confidence

    det_rows = _crossing_rows()
    det = _write_det(tmp_path, det_rows)
    out = tmp_path / "o.txt"
    r = runner.invoke(app, ["track", str(det), "-t", "boxtrack", "--targets", "2", "--offline", "--set", "n_init=2",
                            "-o", str(out)])
    assert r.exit_code == 0, r.output
    rows = np.loadtxt(out, delimiter=",")
    assert set(np.unique(rows[:, 1]).tolist()) == {1, 2}
    assert np.bincount(rows[:, 0].astype(int)).max() == 2
    expected = track_closed_set(det_rows, 2, 30.0, n_frames=60, online={"n_init": 2})  # no seqinfo: 30 frames/s
    expected[:, 6] = assignment_confidence(expected, 30.0)  # column 7: the rows' identity confidence
    np.testing.assert_allclose(rows, expected, atol=1e-3)


def _points_csv(tmp_path: Path, frames: int = 80) -> tuple[Path, Path]:
    rng = np.random.default_rng(0)
    start = np.array([[50.0, 50.0], [150.0, 60.0], [100.0, 160.0]])
    vel = np.array([[1.0, 0.5], [-0.8, 0.7], [0.3, -1.0]])
    lines, gt = ["frame,x,y"], []
    for f in range(1, frames + 1):
        pos = start + vel * f
        order = rng.permutation(3)  # anonymous points: any order
        for i in order:
            lines.append(f"{f},{pos[i, 0]:.2f},{pos[i, 1]:.2f}")
            gt.append(f"{f},{i + 1},{pos[i, 0]:.2f},{pos[i, 1]:.2f}")
    (tmp_path / "points.csv").write_text("\n".join(lines) + "\n")
    (tmp_path / "gt.csv").write_text("frame,id,x,y\n" + "\n".join(gt) + "\n")
    return tmp_path / "points.csv", tmp_path / "gt.csv"


@pytest.mark.parametrize("offline", [False, True])
def test_points_in_tracked_and_scored_with_eval_points(tmp_path, offline):
    points, gt = _points_csv(tmp_path)
    out = tmp_path / "tracks.txt"
    args = ["track", "--points", str(points), "-t", "boxtrack", "--targets", "3", "-o", str(out)]
    r = runner.invoke(app, args + (["--offline"] if offline else []))
    assert r.exit_code == 0, r.output
    assert "points: 240 in 80 frames" in _one_line_error(r)
    assert len(np.unique(read_mot(out).track_id)) == 3
    js = tmp_path / "s.json"
    r = runner.invoke(app, ["eval", "--points", "--gt", str(gt), "--results", str(out), "--radius", "5",
                            "--json", str(js)])
    assert r.exit_code == 0, r.output
    import json

    (row,) = json.loads(js.read_text())["tables"]["scores"]
    idf1 = row["metrics"]["idf1"]
    assert idf1 > (0.99 if offline else 0.9)


def test_points_and_eval_refusals(tmp_path):
    points, gt = _points_csv(tmp_path)
    r = runner.invoke(app, ["track", "--points", str(points), str(points), "-o", str(tmp_path / "t.txt")])
    assert r.exit_code != 0 and "--points: the points are the input" in _one_line_error(r)
    r = runner.invoke(app, ["eval", "--points", "--gt", str(gt), "--results", str(points)])
    assert r.exit_code != 0 and "--radius" in _one_line_error(r)


@pytest.mark.parametrize("offline", [False, True])
def test_points_annotated_on_white_frames_or_on_their_video(tmp_path, offline):
    """--points --annotate draws the tracks on white frames, one a point frame, or on --video's frames."""
    from lookalike.io.video_frames import read_frames

    points, _ = _points_csv(tmp_path)
    base = ["track", "--points", str(points), "-t", "boxtrack", "--targets", "3", "-o", str(tmp_path / "t.txt")]
    base += ["--offline"] if offline else []
    r = runner.invoke(app, [*base, "--annotate", str(tmp_path / "white.mp4")])
    assert r.exit_code == 0, r.output
    frames = list(read_frames(tmp_path / "white.mp4"))
    assert len(frames) == 80 and "annotated video" in r.output
    assert (frames[0] > 200).mean() > 0.7 and (frames[-1] < 200).any()  # white (a caption band), tracks drawn
    video = _arena(tmp_path / "arena.avi")
    r = runner.invoke(app, [*base, "--video", str(video), "--annotate", str(tmp_path / "on.mp4")])
    assert r.exit_code == 0, r.output
    assert len(list(read_frames(tmp_path / "on.mp4"))) == 30
    r = runner.invoke(app, [*base, "--video", str(video)])
    assert r.exit_code == 2 and "--points --video: the video is only drawn on, with --annotate" in _one_line_error(r)


def _arena(path: Path, frames: int = 30) -> Path:
    import cv2

    writer = cv2.VideoWriter(str(path), cv2.VideoWriter_fourcc(*"MJPG"), 10, (160, 120))
    for k in range(frames):
        img = np.full((120, 160, 3), 215, np.uint8)
        for x, y, vx in ((20, 20, 3), (140, 60, -3), (30, 100, 2)):
            cv2.circle(img, (int(x + vx * k), y), 7, (35, 35, 35), -1)
        writer.write(img)
    writer.release()
    return path


def test_blob_settings_estimated_printed_and_overridden(tmp_path):
    video = _arena(tmp_path / "arena.avi")
    out = tmp_path / "t.txt"
    confident = ["--set", "high_score=0.5", "--set", "birth_score=0.5"]  # 90 blobs: too few to self-calibrate
    r = runner.invoke(app, ["track", "--video", str(video), "--detector", "blob", "-t", "boxtrack", "--targets", "3",
                            "--offline", *confident, "-o", str(out), "--save-detections", str(tmp_path / "t.det.txt")])
    assert r.exit_code == 0, r.output
    text = _one_line_error(r)
    assert "estimated from the video" in text and "polarity=dark" in text and "threshold=" in text
    assert len(np.unique(read_mot(out).track_id)) == 3
    again = tmp_path / "again.txt"  # the blob boxes re-tracked from their det.txt, same closed set
    r = runner.invoke(app, ["track", "--video", str(video), "--detections", str(tmp_path / "t.det.txt"), "-t",
                            "boxtrack", "--targets", "3", "--offline", *confident, "-o", str(again)])
    assert r.exit_code == 0, r.output
    np.testing.assert_array_equal(np.loadtxt(again, delimiter=","), np.loadtxt(out, delimiter=","))
    annotated = tmp_path / "a.mp4"  # the closed set's identities drawn on the video
    r = runner.invoke(app, ["track", "--video", str(video), "--detector", "blob", "-t", "boxtrack", "--targets", "3",
                            "--offline", *confident, "--annotate", str(annotated), "-o", str(out)])
    assert r.exit_code == 0, r.output
    np.testing.assert_array_equal(np.loadtxt(again, delimiter=","), np.loadtxt(out, delimiter=","))
    assert sum(1 for _ in read_frames(annotated)) == sum(1 for _ in read_frames(video))
    config, estimate = auto_blob_config(video, ["threshold=50", "open_px=5"], 3)
    assert estimate is not None and (config.threshold, config.open_px) == (50.0, 5)
    assert config.polarity == estimate.config.polarity == "dark"
    config, estimate = auto_blob_config(video, ["threshold=50", "polarity=dark", "min_area_px=5",
                                                "max_area_px=500"])
    assert estimate is None and config.max_area_px == 500


def test_blob_cache_serves_identical_rows_and_never_stale_ones(tmp_path):
    video = _arena(tmp_path / "arena.avi")
    config, _ = auto_blob_config(video, [], cache=tmp_path / "c")
    fresh = cached_blob_detections(video, config, cache=False)
    first = cached_blob_detections(video, config, cache=tmp_path / "c")
    again = cached_blob_detections(video, config, cache=tmp_path / "c")
    np.testing.assert_array_equal(fresh.rows, first.rows)
    np.testing.assert_array_equal(first.rows, again.rows)
    assert len(list((tmp_path / "c" / "blobs").glob("*.npz"))) == 1
    from dataclasses import replace

    assert detection_cache_key(video, config) != detection_cache_key(video, replace(config, threshold=99.0))
    other = _arena(tmp_path / "other.avi", frames=20)  # other content, other key
    assert detection_cache_key(video, config) != detection_cache_key(other, config)
    assert cached_blob_detections(other, config, cache=tmp_path / "c").frames == 20


def test_blobs_are_split_into_parts_only_for_a_reader_of_parts(tmp_path):
    import cv2

    video = tmp_path / "cross.avi"  # two animals that meet and merge into one blob
    writer = cv2.VideoWriter(str(video), cv2.VideoWriter_fourcc(*"MJPG"), 10, (160, 120))
    for k in range(40):
        img = np.full((120, 160, 3), 215, np.uint8)
        for x, vx in ((20, 3), (140, -3)):
            cv2.circle(img, (int(x + vx * k), 60), 7, (35, 35, 35), -1)
        writer.write(img)
    writer.release()
    config, _ = auto_blob_config(video, [], 2, cache=tmp_path / "c")
    cache = tmp_path / "c"
    plain = cached_blob_detections(video, config, cache=cache, split=False)  # e.g. --online: nothing reads parts
    assert not plain.split and np.isnan(plain.parts).all()
    assert load_blob_detections(video, config, cache, split=False) is not None
    assert load_blob_detections(video, config, cache) is None  # a reader of parts does not take them
    split = cached_blob_detections(video, config, cache=cache)  # detected again, with parts, and stored
    assert split.split and not np.isnan(split.parts).all()
    np.testing.assert_array_equal(split.rows, plain.rows)
    np.testing.assert_array_equal(split.shapes, plain.shapes)
    again = load_blob_detections(video, config, cache, split=False)  # parts serve every run after that
    assert again is not None and again.split
    np.testing.assert_array_equal(again.parts, split.parts)


def _seq(dataset: str, name: str = "s", n_targets: int | None = None) -> RealSequence:
    rows = _crossing_rows()
    xywh = [rows[rows[:, 0] == f, 2:6] for f in range(1, 61)]
    score = [rows[rows[:, 0] == f, 6] for f in range(1, 61)]
    return RealSequence(dataset, name, 10.0, 60, xywh, score, n_targets=n_targets)


def test_bench_entries_params_row_and_closed_offline():
    seqs = [_seq("mot15", "ADL-Rundle-6"), _seq("pigs", "pigs", 2)]
    entry = params_entry("runs/mine.json", "boxtrack", {"n_init": 1}, ["mot15/ADL-Rundle-6"], seqs)
    assert entry.label == "mine (tuned on this data)" and not entry.tuned
    assert params_entry("mine.json", "boxtrack", {}, ["mot15/KITTI-13"], seqs).label == "mine"
    labels = [e.label for e, _ in job_pairs(default_entries(["boxtrack"], []), [seqs[1]])]
    assert "boxtrack-closed-offline" in labels and "boxtrack (tuned on this data)" in labels  # pig parameters
    hexbug = _seq("hexbug", "clip")
    labels = [e.label for e, _ in job_pairs(default_entries(["boxtrack"], []), [hexbug])]
    assert "boxtrack (tuned on this data)" in labels
    rows = track_rows(Entry("c", "boxtrack", closed_set=True, closed_offline=True), seqs[1])
    assert set(np.unique(rows[:, 1]).tolist()) == {1, 2}


def test_bench_real_params_option(tmp_path):
    data = Path(__file__).resolve().parents[1].parent / "shared" / "data"
    if not (data / "mot15" / "TUD-Campus").is_dir():
        pytest.skip(f"real data not found at {data} (../shared/data)")
    params = save_params(tmp_path / "campus.json", "boxtrack", {"n_init": 2}, chosen_on=["mot15/TUD-Campus"],
                         criterion="idf1", trials=1)
    import json

    out = tmp_path / "r.json"
    r = runner.invoke(app, ["bench", "real", "--data", str(data), "--datasets", "mot15", "--sequence", "TUD-Campus",
                            "--peers", "none", "--trackers", "sort", "--params", str(params), "--json", str(out)])
    assert r.exit_code == 0, r.output
    names = {row["tracker"] for row in json.loads(out.read_text())["tables"]["datasets"]}
    assert names == {"sort", "campus (tuned on this data)"}
