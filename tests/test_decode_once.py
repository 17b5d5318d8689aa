"""``lookalike track`` decodes a video once (issue 45): the frames OpenCV converts to BGR are counted.

A full decode is one conversion of every frame (``read``, or ``grab`` + ``retrieve``). The blob detector's settings
estimate and median background share one cheaper sampled pass first: every frame grabbed (demuxed and decoded), only
the sampled ones converted."""

from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from lookalike.cli import app
from lookalike.io import MotTable, read_mot, write_mot
from tests.test_track_blobs import FRAMES, _write_video

cv2 = pytest.importorskip("cv2")
runner = CliRunner()
SAMPLE = 25  # frames the blob settings estimate and background read (BlobConfig.history)


@pytest.fixture
def counts(monkeypatch, tmp_path) -> dict[str, int]:
    """Frames converted (``read``/``retrieve``) and only grabbed, over every ``cv2.VideoCapture`` of the test."""
    monkeypatch.setenv("LOOKALIKE_CACHE", str(tmp_path / "cache"))
    seen = {"converted": 0, "grabbed": 0}
    real = cv2.VideoCapture

    class Counted:
        def __init__(self, *args, **kwargs):
            self._cap = real(*args, **kwargs)

        def read(self, *args):
            ok, image = self._cap.read(*args)
            seen["converted"] += bool(ok)
            return ok, image

        def grab(self):
            ok = self._cap.grab()
            seen["grabbed"] += bool(ok)
            return ok

        def retrieve(self, *args):
            ok, image = self._cap.retrieve(*args)
            seen["converted"] += bool(ok)
            seen["grabbed"] -= bool(ok)  # (a grab converted is a read)
            return ok, image

        def __getattr__(self, name):
            return getattr(self._cap, name)

    monkeypatch.setattr(cv2, "VideoCapture", Counted)
    return seen


@pytest.fixture(scope="module")
def video(tmp_path_factory) -> Path:
    return _write_video(tmp_path_factory.mktemp("decode") / "discs.avi")


def _track(*args: str) -> None:
    r = runner.invoke(app, ["track", *args])
    assert r.exit_code == 0, r.output


BLOB = ("--detector", "blob", "--blob", "polarity=dark", "--blob", "min_area_px=20")


@pytest.mark.parametrize("extra", [("-t", "sort"), ("-t", "boxtrack"), ("-t", "sort", "--annotate", "a.mp4"),
                                   ("-t", "boxtrack", "--targets", "3", "--online", "--annotate", "a.mp4"),
                                   ("-t", "deepsort", "--features", "learned"), ("-t", "deepsort")])
def test_blob_video_is_decoded_once(video, tmp_path, counts, monkeypatch, extra):
    monkeypatch.chdir(tmp_path)
    _track("--video", str(video), *BLOB, *extra, "-o", "t.txt")
    assert counts == {"converted": FRAMES + SAMPLE, "grabbed": FRAMES - SAMPLE} or (
        # (fewer frames than the sample: the sampled pass converts every frame)
        FRAMES <= SAMPLE and counts == {"converted": 2 * FRAMES, "grabbed": 0})
    assert not (tmp_path / "t.det.txt").exists()
    counts.update(converted=0, grabbed=0)  # again, the detections cached: one decode when drawing, else none
    _track("--video", str(video), *BLOB, *extra, "-o", "t.txt")
    assert counts == {"converted": FRAMES if "a.mp4" in extra or "deepsort" in extra else 0, "grabbed": 0}


@pytest.mark.parametrize("extra", [(), ("--annotate", "a.mp4"), ("-t", "boxtrack", "--targets", "3"),
                                   ("-t", "deepsort"), ("-t", "diversort", "--features", "handcrafted")])
def test_video_with_detections_is_decoded_once(video, tmp_path, counts, monkeypatch, extra):
    monkeypatch.chdir(tmp_path)
    _track("--video", str(video), *BLOB, "-t", "sort", "-o", "first.txt", "--save-detections", "d.txt")
    counts.update(converted=0, grabbed=0)
    _track("--video", str(video), "--detections", "d.txt", *extra, "-o", "t.txt")
    assert counts == {"converted": FRAMES, "grabbed": 0}
    assert len(read_mot(tmp_path / "t.txt")) > 0


@pytest.mark.parametrize("extra", [("-t", "sort"), ("-t", "sort", "--annotate", "a.mp4"), ("-t", "deepsort"),
                                   ("-t", "diversort", "--features", "handcrafted", "--annotate", "a.mp4")])
def test_onnx_detector_video_is_decoded_once(video, tmp_path, counts, monkeypatch, extra):
    from tests.test_onnx_detector import _darkness_grid_model

    monkeypatch.chdir(tmp_path)
    model = _darkness_grid_model(tmp_path / "dark.onnx")
    _track("--video", str(video), "--detector", str(model), "--blob", "score=0.15", *extra, "-o", "t.txt")
    assert counts == {"converted": FRAMES, "grabbed": 0}
    assert not (tmp_path / "t.det.txt").exists()


@pytest.mark.parametrize("extra", [("-t", "deepsort"), ("-t", "boxtrack", *BLOB)])
def test_a_whole_video_step_then_drawing_decodes_twice(video, tmp_path, counts, monkeypatch, extra):
    """Features fitted on the video (``--features video``) or a team size inferred from its blob counts are known
    only after a pass over the whole video: drawing then decodes it again."""
    monkeypatch.chdir(tmp_path)
    _track("--video", str(video), *BLOB, "-t", "sort", "-o", "first.txt", "--save-detections", "d.txt")
    counts.update(converted=0, grabbed=0)
    monkeypatch.setenv("LOOKALIKE_CACHE", str(tmp_path / "fresh"))
    source = () if "boxtrack" in extra else ("--detections", "d.txt")
    _track("--video", str(video), *source, *extra, "--annotate", "a.mp4", "-o", "t.txt")
    sampled = (SAMPLE, FRAMES - SAMPLE) if "boxtrack" in extra else (0, 0)  # (the blob settings' sampled pass)
    assert counts == {"converted": 2 * FRAMES + sampled[0], "grabbed": sampled[1]}


def test_robot_pixels_video_is_decoded_once(tmp_path, counts, monkeypatch):
    monkeypatch.chdir(tmp_path)
    r = runner.invoke(app, ["simulate", "--preset", "m3n2", "--frames", "12", "--seed", "3", "-o", "."])
    assert r.exit_code == 0, r.output
    assert runner.invoke(app, ["render-robots", "m3n2-000003.jsonl", "-o", "clip.mp4"]).exit_code == 0
    counts.update(converted=0, grabbed=0)
    _track("--video", "clip.mp4", "--pipeline", "robots", "--reports", "m3n2-000003.jsonl", "-t", "kalman_ha",
           "--annotate", "a.mp4", "-o", "t.txt")
    assert counts == {"converted": 12, "grabbed": 0}


class _Seen:
    """A tracker keeping the boxes and features it is given, and reporting no tracks."""

    def __init__(self) -> None:
        self.seen: list[np.ndarray] = []

    def reset(self) -> None:
        self.seen = []

    def update(self, frame):
        det = frame.detections
        self.seen.append(np.hstack([det.xywh, det.feature]))
        return []


def test_features_fitted_in_the_pass_are_those_fitted_first(video, tmp_path, monkeypatch):
    """A tracker given :class:`VideoFeatures` (fitted in the pass, one decode) sees the features fitted in a pass of
    their own first, also with the detector run in the pass; boxes scored below ``min_score`` are left out of both."""
    from lookalike.pipeline.tracking import VideoFeatures, fit_video_features, track_video
    from lookalike.types import Detections

    monkeypatch.chdir(tmp_path)
    _track("--video", str(video), *BLOB, "-t", "sort", "-o", "first.txt", "--save-detections", "d.txt")
    rows = np.loadtxt(tmp_path / "d.txt", delimiter=",")
    rows[::4, 6] = 0.2  # (some boxes below min_score)
    table = MotTable.from_rows(rows)
    by_frame = [table.frame == k + 1 for k in range(FRAMES)]

    def detect(image):
        keep = by_frame.pop(0) & (table.conf >= 0.5)
        return Detections(xywh=table.xywh[keep], score=table.conf[keep])

    spec = VideoFeatures(max_crops=40)  # (sampled: one block of 10 frames in every few)
    assert spec.blocks(int((table.conf >= 0.5).sum())) > 1
    want, got, found = _Seen(), _Seen(), _Seen()
    track_video(video, table, want, fit_video_features(video, table, min_score=0.5, max_crops=40), min_score=0.5)
    track_video(video, table, got, spec, min_score=0.5)
    track_video(video, MotTable.from_rows(np.zeros((0, 10))), found, spec, detect=detect)
    assert len(want.seen) == FRAMES and sum(map(len, want.seen)) == (table.conf >= 0.5).sum()
    for a, b, c in zip(want.seen, got.seen, found.seen):
        np.testing.assert_array_equal(a, b)
        np.testing.assert_array_equal(a, c)


def test_saved_detections_are_the_rows_tracked(video, tmp_path, monkeypatch):
    """--save-detections writes the boxes found; tracking that file gives the same result."""
    monkeypatch.setenv("LOOKALIKE_CACHE", str(tmp_path / "cache"))
    monkeypatch.chdir(tmp_path)
    _track("--video", str(video), *BLOB, "-t", "sort", "--annotate", "a.mp4", "-o", "a.txt", "--save-detections",
           "d.txt")
    _track("--video", str(video), "--detections", "d.txt", "-t", "sort", "-o", "b.txt")
    assert len(read_mot(tmp_path / "d.txt")) == 3 * FRAMES
    np.testing.assert_array_equal(np.loadtxt("a.txt", delimiter=","), np.loadtxt("b.txt", delimiter=","))
    write_mot(tmp_path / "x.txt", np.zeros((0, 10)))
    r = runner.invoke(app, ["track", "x.txt", "-o", "y.txt", "--save-detections", "z.txt"])
    assert r.exit_code == 2 and "--save-detections: only with --video FILE --detector" in r.output
