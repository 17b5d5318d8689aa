"""Features fitted on the video (``--features video``) wait in a temporary file during the pass
(:class:`~lookalike.pipeline.spill.FrameSpill`): the tracker sees what it saw with everything kept in memory, and the
file is gone afterwards, also when the run fails or is interrupted half-way."""

import tempfile
from pathlib import Path

import numpy as np
import pytest

import lookalike.pipeline.tracking as tracking
from lookalike.io import MotTable
from lookalike.pipeline.spill import FrameSpill
from lookalike.trackers import make_tracker
from lookalike.types import Detections
from tests.test_decode_once import _Seen
from tests.test_track_blobs import _write_video

pytest.importorskip("cv2")
FRAMES = 40
# (start x, start y, vx, vy) px and px/frame: two discs cross the third's lane.
DISCS = ((20, 20, 3, 0), (140, 60, -3, 0), (30, 100, 2, 0), (80, 10, 0, 2))


@pytest.fixture(scope="module")
def clip(tmp_path_factory) -> tuple[Path, MotTable]:
    """A generated video of dark discs and their boxes (none in frame 6)."""
    video = _write_video(tmp_path_factory.mktemp("spill") / "discs.avi", DISCS, FRAMES)
    rows = [[k + 1, -1, x + vx * k - 8, y + vy * k - 8, 16, 16, 0.5 + 0.1 * (i % 4), -1, -1, -1]
            for k in range(FRAMES) for i, (x, y, vx, vy) in enumerate(DISCS) if k != 5]
    return video, MotTable.from_rows(np.array(rows, dtype=float))


class _InMemory:
    """The reference: every frame's detections and features kept in a list."""

    def __init__(self) -> None:
        self.kept: list[tuple[Detections, np.ndarray]] = []
        self.boxes = 0

    def append(self, det: Detections, feature: np.ndarray) -> None:
        self.kept.append((det, feature))
        self.boxes += len(det)

    def read(self):
        for det, feature in self.kept:
            yield det.replace(feature=feature)

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        pass


@pytest.fixture
def spills(monkeypatch, tmp_path) -> list[FrameSpill]:
    """The spill files :func:`track_video` opens, made in a temporary folder of the test's own."""
    made: list[FrameSpill] = []

    class Recorded(FrameSpill):
        def __init__(self) -> None:
            super().__init__()
            made.append(self)

    (tmp_path / "tmp").mkdir()
    monkeypatch.setattr(tempfile, "tempdir", str(tmp_path / "tmp"))
    monkeypatch.setattr(tracking, "FrameSpill", Recorded)
    return made


def _gone(made: list[FrameSpill], tmp_path: Path, runs: int = 1) -> bool:
    """Whether ``runs`` spill files were opened, all closed, and nothing is left in the temporary folder."""
    return len(made) == runs and all(s.closed for s in made) and not any((tmp_path / "tmp").iterdir())


def test_frames_read_back_bit_for_bit(spills, tmp_path):
    frames = [Detections(xywh=np.array([[1.5, 2.0, 3.0, 4.0], [0.1, 0.2, 0.3, 1e-300]]), score=[0.25, 1 / 3]),
              Detections.empty(),
              Detections(xywh=np.array([[5.0, 6.0, 7.0, 8.0]]), label=[7], position=[[1.0, -2.0]], heading=[0.5])]
    features = [np.array([[np.pi, -0.0], [1e-310, 2.0]]), np.zeros((0, 2)), np.array([[np.e, 1.0]])]
    with tracking.FrameSpill() as spill:
        for det, feature in zip(frames, features):
            spill.append(det, feature)
        assert (spill.frames, spill.boxes) == (3, 3)
        for _ in range(2):  # (read as often as needed)
            back = list(spill.read())
            assert len(back) == 3
            for det, feature, got in zip(frames, features, back):
                assert got.feature is not None and got.feature.dtype == np.float64
                np.testing.assert_array_equal(got.feature, feature)
                for name in ("xywh", "score", "position", "heading", "heading_std", "label"):
                    want, have = getattr(det, name), getattr(got, name)
                    assert (want is None) == (have is None), name
                    if want is not None:
                        assert have.dtype == want.dtype and have.tobytes() == want.tobytes(), name
    assert _gone(spills, tmp_path)


@pytest.mark.parametrize("name", ["deepsort", "diversort"])
def test_spilled_pass_tracks_as_the_pass_kept_in_memory(clip, spills, tmp_path, monkeypatch, name):
    video, table = clip
    spec = tracking.VideoFeatures(max_crops=40)  # (sampled: one block of 10 frames in every few)
    assert spec.blocks(len(table)) > 1
    spilled, spilled_seen = tracking.track_video(video, table, make_tracker(name), spec), _Seen()
    tracking.track_video(video, table, spilled_seen, spec, min_score=0.55)
    assert _gone(spills, tmp_path, runs=2)
    monkeypatch.setattr(tracking, "FrameSpill", _InMemory)
    kept, kept_seen = tracking.track_video(video, table, make_tracker(name), spec), _Seen()
    tracking.track_video(video, table, kept_seen, spec, min_score=0.55)
    assert spilled.frames == FRAMES and len(spilled.rows) > 0
    np.testing.assert_array_equal(spilled.rows, kept.rows)
    assert len(spilled_seen.seen) == len(kept_seen.seen) == FRAMES
    for a, b in zip(spilled_seen.seen, kept_seen.seen):
        np.testing.assert_array_equal(a, b)


class _Failing(_Seen):
    def update(self, frame):
        if frame.index == 17:
            raise RuntimeError("tracker failed")
        return super().update(frame)


def test_spill_is_removed_when_the_run_fails(clip, spills, tmp_path):
    video, table = clip
    with pytest.raises(RuntimeError, match="tracker failed"):  # while tracking, after the fit
        tracking.track_video(video, table, _Failing(), tracking.VideoFeatures())
    assert _gone(spills, tmp_path)
    seen = {"frames": 0}

    def interrupt() -> None:  # Ctrl-C while the features are being computed
        seen["frames"] += 1
        if seen["frames"] == 12:
            raise KeyboardInterrupt

    spills.clear()
    with pytest.raises(KeyboardInterrupt):
        tracking.track_video(video, table, _Seen(), tracking.VideoFeatures(), advance=interrupt)
    assert _gone(spills, tmp_path)
