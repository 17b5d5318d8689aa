"""``lookalike.pipeline.run``: a ``track`` request run from Python, what it did told through ``on_event`` and
returned; the rows are those of ``lookalike track``."""

from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from lookalike.cli import app
from lookalike.io import read_mot
from lookalike.pipeline import Event, TrackRequest, run
from tests.test_track_blobs import FRAMES, _write_video

runner = CliRunner()


@pytest.fixture(scope="module")
def scene(tmp_path_factory) -> tuple[Path, Path]:
    """A video of three discs and the detections a blob detector found on it."""
    pytest.importorskip("cv2")
    root = tmp_path_factory.mktemp("run")
    video = _write_video(root / "discs.avi")
    r = runner.invoke(app, ["track", "--video", str(video), "--detector", "blob", "--blob", "polarity=dark",
                            "--blob", "min_area_px=20", "-o", str(root / "first.txt"), "--save-detections",
                            str(root / "det.txt")])
    assert r.exit_code == 0, r.output
    return video, root / "det.txt"


def test_files_and_video_runs_tell_and_return_what_they_wrote(scene, tmp_path):
    video, det = scene
    events: list[Event] = []
    files = run(TrackRequest(tmp_path / "f.txt", "boxtrack", path=det, min_score=0.5), events.append)
    assert files.branch == "files" and files.written == [tmp_path / "f.txt"] and files.sequences == 1
    assert files.stats.frames == FRAMES
    assert any(e.kind == "warn" and "score" in e.text for e in events)  # (blob scores: all 1)
    starts = [e for e in events if e.kind == "start"]
    assert starts[0] == Event("start", "sequences", 1) and Event("end", "sequences") in events
    result = next(e for e in events if e.kind == "result")
    assert result.name == "boxtrack" and result.text.startswith(": 1 sequence(s), 30 frames")
    assert events[-1].kind == "line" and events[-1].text.startswith("doubtful: ")  # (each row's confidence added)
    assert 0 < sum(e.count for e in events if e.kind == "advance" and e.text == starts[1].text) <= FRAMES
    events.clear()
    vid = run(TrackRequest(tmp_path / "v.txt", "deepsort", video=str(video), detections=det), events.append)
    assert vid.branch == "video" and vid.video is not None and vid.video.frames == FRAMES
    assert vid.written == [tmp_path / "v.txt", tmp_path / "v.health.csv"]
    assert sum(e.count for e in events if e.kind == "advance") == FRAMES
    r = runner.invoke(app, ["track", "--video", str(video), "--detections", str(det), "-t", "deepsort", "-o",
                            str(tmp_path / "cli.txt")])
    assert r.exit_code == 0, r.output
    assert (tmp_path / "cli.txt").read_bytes() == (tmp_path / "v.txt").read_bytes()


def test_offline_and_point_runs(scene, tmp_path):
    """The closed set over a file and over a video's detections, and points tracked and drawn: one result each."""
    video, det = scene
    events: list[Event] = []
    closed = run(TrackRequest(tmp_path / "c.txt", "boxtrack", path=det, targets=3, offline=True), events.append)
    on_video = run(TrackRequest(tmp_path / "cv.txt", "boxtrack", video=str(video), detections=det, targets=3,
                                offline=True, annotate=tmp_path / "cv.mp4"), events.append)
    assert closed.written == [tmp_path / "c.txt"] and on_video.written == [tmp_path / "cv.txt"]
    assert set(read_mot(tmp_path / "c.txt").track_id) == set(read_mot(tmp_path / "cv.txt").track_id) == {1, 2, 3}
    assert (tmp_path / "cv.mp4").stat().st_size > 0
    rows = read_mot(det)
    centres = np.column_stack([rows.frame, rows.xywh[:, :2] + rows.xywh[:, 2:] / 2])
    np.savetxt(tmp_path / "p.csv", centres, delimiter=",", fmt="%g")
    points = run(TrackRequest(tmp_path / "p.txt", "boxtrack", points=tmp_path / "p.csv", targets=3,
                              annotate=tmp_path / "p.mp4"), events.append)
    assert points.branch == "points" and len(read_mot(tmp_path / "p.txt")) == len(rows)
    results = [e.text for e in events if e.kind == "result"]
    assert results[0] == f", offline closed set of 3: 1 sequence(s) → {tmp_path / 'c.txt'}"
    assert results[1].startswith(", offline closed set of 3: 3 identities") and results[2].startswith(", online: 3")
    assert Event("line", f"annotated video → {tmp_path / 'p.mp4'}") in events


def test_a_detector_run_finds_and_tracks_in_one_pass(scene, tmp_path, monkeypatch):
    """Blobs found while tracked: the rows of the detections saved, tracked as a file."""
    video, det = scene
    monkeypatch.setenv("LOOKALIKE_CACHE", str(tmp_path / "cache"))
    events: list[Event] = []
    found = run(TrackRequest(tmp_path / "b.txt", "sort", video=str(video), detector="blob", blob=["polarity=dark",
                             "min_area_px=20"], annotate=tmp_path / "b.mp4", save_detections=tmp_path / "d.txt"),
                events.append)
    assert found.branch == "blobs" and found.video is not None and found.video.frames == FRAMES
    assert Event("line", f"blob detector: 90 boxes in {FRAMES} frames → {tmp_path / 'd.txt'}") in events
    run(TrackRequest(tmp_path / "f.txt", "sort", path=tmp_path / "d.txt"))
    video_rows, file_rows = (np.loadtxt(tmp_path / f, delimiter=",") for f in ("b.txt", "f.txt"))
    keep = [0, 1, 2, 3, 4, 5, 7, 8, 9]  # (column 7, the identity confidence, depends on the frame rate: 10 vs 30)
    np.testing.assert_array_equal(video_rows[:, keep], file_rows[:, keep])


def test_bad_requests_are_refused_in_one_line(scene, tmp_path):
    video, det = scene
    with pytest.raises(ValueError, match="--features"):
        run(TrackRequest(tmp_path / "v.txt", "deepsort", video=str(video), detections=det, features="nope"))
    with pytest.raises(ValueError, match="a live source; drop --fps"):
        run(TrackRequest(tmp_path / "b.txt", video="0", detector="blob", fps=10.0))
    with pytest.raises(ValueError, match="a live source; drop --offline"):  # (not first "needs --targets N")
        run(TrackRequest(tmp_path / "b.txt", video="0", detector="blob", offline=True))
    with pytest.raises(ValueError, match="--detector: choose one of blob or FILE.onnx"):
        run(TrackRequest(tmp_path / "b.txt", video=str(video), detector="yolo"))
    with pytest.raises(ValueError, match="unknown tracker"):
        run(TrackRequest(tmp_path / "f.txt", "nope", path=det))
    with pytest.raises(ValueError, match="--features learned: only with --video"):  # (was ignored)
        run(TrackRequest(tmp_path / "f.txt", "deepsort", path=det, features="learned"))
    assert not (tmp_path / "f.txt").exists()


def test_file_and_video_runs_announce_their_length_to_boxtrack(scene, tmp_path, monkeypatch):
    """A run of known length tells the tracker how many frames follow (boxtrack decides from it whether its compiled
    kernels pay); the rows do not depend on it."""
    from lookalike.trackers.boxtrack import BoxTrack

    video, det = scene
    seq = tmp_path / "data" / "discs"
    (seq / "det").mkdir(parents=True)
    (seq / "det" / "det.txt").write_bytes(det.read_bytes())
    (seq / "seqinfo.ini").write_text(f"[Sequence]\nname=discs\nframeRate=30\nseqLength={FRAMES + 5}\n")
    heard: list[int] = []
    monkeypatch.setattr(BoxTrack, "expect", lambda self, frames: heard.append(frames))
    run(TrackRequest(tmp_path / "out", "boxtrack", path=seq.parent, min_score=0.5), lambda e: None)
    run(TrackRequest(tmp_path / "f.txt", "boxtrack", path=det, min_score=0.5), lambda e: None)
    run(TrackRequest(tmp_path / "v.txt", "boxtrack", video=str(video), detections=det), lambda e: None)
    assert heard == [FRAMES + 5, 0, FRAMES]  # (a lone file's length is unknown until read: 0, nothing decided)


def test_a_video_too_short_for_the_offline_closed_set_says_the_online_one_was_written(tmp_path):
    from lookalike.pipeline.closed import offline_video

    det = np.array([[1, -1, 10 + 30 * k, 20, 12, 12, 0.9, -1, -1, -1] for k in range(2)], float)  # one frame
    events: list[Event] = []
    offline_video(det, tmp_path / "o.txt", 2, {}, 10.0, 1, 0.0, events.append)
    lines = [e.text for e in events if e.kind == "line"]
    result = next(e.text for e in events if e.kind == "result")
    assert any("online closed set's result" in text for text in lines), lines
    assert result.startswith(", online closed set (the note above) of 2:"), result
