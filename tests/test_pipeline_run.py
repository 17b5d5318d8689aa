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
    assert starts[0] == Event("start", "sequences", 1) and events[-1] == Event("end", "sequences")
    assert 0 < sum(e.count for e in events if e.kind == "advance" and e.text == starts[1].text) <= FRAMES
    events.clear()
    vid = run(TrackRequest(tmp_path / "v.txt", "deepsort", video=str(video), detections=det), events.append)
    assert vid.branch == "video" and vid.video is not None and vid.video.frames == FRAMES
    assert vid.written == [tmp_path / "v.txt", tmp_path / "v.health.csv"]
    assert sum(e.count for e in events if e.kind == "advance") == FRAMES
    r = runner.invoke(app, ["track", "--video", str(video), "--detections", str(det), "-t", "deepsort", "-o",
                            str(tmp_path / "cli.txt")])
    assert r.exit_code == 0, r.output
    cli = read_mot(tmp_path / "cli.txt")  # (the command also writes each row's confidence)
    got = read_mot(tmp_path / "v.txt")
    np.testing.assert_array_equal(np.column_stack([cli.frame, cli.track_id, cli.xywh]),
                                  np.column_stack([got.frame, got.track_id, got.xywh]))


def test_bad_requests_are_refused_in_one_line(scene, tmp_path):
    video, det = scene
    with pytest.raises(ValueError, match="--features"):
        run(TrackRequest(tmp_path / "v.txt", "deepsort", video=str(video), detections=det, features="nope"))
    with pytest.raises(ValueError, match="takes the online files and video branches, not blobs"):
        run(TrackRequest(tmp_path / "b.txt", video=str(video), detector="blob"))
    with pytest.raises(ValueError, match="unknown tracker"):
        run(TrackRequest(tmp_path / "f.txt", "nope", path=det))
