"""``lookalike track --video``: rendered diver scenes (MP4 and image folder) end to end, merges,
uncertain identities and the health banner, and real MOT17 pixels."""

import csv
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from lookalike.cli import app
from lookalike.io import MotTable, read_mot, write_mot
from lookalike.pipeline.tracking import track_video
from lookalike.sim.divers import DetectorModel, DiverScenario, simulate_divers
from lookalike.trackers import DiverSort, HealthConfig, TrackStatus, make_tracker
from lookalike.types import TrackSnapshot
from lookalike.viz import read_frames, video_info
from lookalike.viz.video import VideoWriter
from lookalike.viz.video_tracking import draw_banner, side_file

runner = CliRunner()
DATA = Path(__file__).resolve().parents[1].parent / "shared" / "data"
FRAMES = 36


@pytest.fixture(scope="module")
def diver_scene(tmp_path_factory):
    """A rendered 3-diver scene as an MP4, an img1 folder (with seqinfo.ini) and its det.txt."""
    root = tmp_path_factory.mktemp("divers")
    sc = DiverScenario(name="t", n_divers=3, frames=FRAMES, image_size=(320, 240), focal_px=210.0, seed=11,
                       detector=DetectorModel(recall=0.9, false_positives=0.2))
    scene = simulate_divers(sc)
    import cv2

    img1 = root / "seq" / "img1"
    img1.mkdir(parents=True)
    (root / "seq" / "seqinfo.ini").write_text(f"[Sequence]\nname=seq\nframeRate=10\nseqLength={FRAMES}\n")
    rows = []
    with VideoWriter(root / "divers.mp4", fps=sc.frame_rate) as writer:
        for frame in scene.frames():
            image = scene.image(frame.index)
            writer.write(image)
            cv2.imwrite(str(img1 / f"{frame.index + 1:06d}.png"), image)
            for box in frame.detections.xywh:
                rows.append([frame.index + 1, -1, *box, 0.9, -1, -1, -1])
    det = write_mot(root / "seq" / "det" / "det.txt", np.array(rows))
    return root, det


def _csv(path: Path) -> list[dict[str, str]]:
    with path.open() as fh:
        return list(csv.DictReader(fh))


def test_diversort_on_mp4_end_to_end(diver_scene, tmp_path):
    root, det = diver_scene
    out, ann = tmp_path / "tracks.txt", tmp_path / "annotated.mp4"
    r = runner.invoke(app, ["track", "--tracker", "diversort", "--video", str(root / "divers.mp4"),
                            "--detections", str(det), "-o", str(out), "--annotate", str(ann), "--team-size", "3",
                            "--features", "divers"])
    assert r.exit_code == 0, r.output
    tracks = read_mot(out)
    assert len(tracks) > FRAMES and tracks.frame.max() <= FRAMES
    assert sum(1 for _ in read_frames(ann)) == FRAMES == sum(1 for _ in read_frames(root / "divers.mp4"))
    assert video_info(ann)[2] == (320, 240)
    merges = side_file(out, "merges")
    assert merges == tmp_path / "tracks.merges.csv" and merges.read_text().startswith("frame,source_id,target_id")
    health = _csv(side_file(out, "health"))
    assert [int(h["frame"]) for h in health] == list(range(1, FRAMES + 1))
    assert "merge(s)" in r.output and "frames/s" in r.output


def test_image_folder_with_missing_detections_flags_health(diver_scene, tmp_path):
    root, det = diver_scene
    table = read_mot(det)
    keep = (table.frame < 15) | (table.frame > 26)  # the detector dies for 12 frames
    rows = np.column_stack([table.frame, table.track_id, table.xywh, table.conf, -np.ones((len(table), 3))])[keep]
    holes = write_mot(tmp_path / "det.txt", rows)
    out, ann = tmp_path / "res" / "tracks.txt", tmp_path / "ann.mp4"
    r = runner.invoke(app, ["track", str(holes), "--tracker", "sort", "--video", str(root / "seq" / "img1"),
                            "-o", str(out), "--annotate", str(ann), "--team-size", "3", "--health-window", "6"])
    assert r.exit_code == 0, r.output
    assert not side_file(out, "merges").exists()  # SORT never merges identities
    health = {int(h["frame"]): h for h in _csv(side_file(out, "health"))}
    assert health[20]["frame_healthy"] == "0" and "empty" in health[20]["flags"]
    assert health[24]["window_healthy"] == "0" and "undercount" in health[24]["window_flags"]
    assert health[5]["frame_healthy"] == "1"
    frames = list(read_frames(ann))
    assert len(frames) == FRAMES

    def banner_red(img: np.ndarray) -> float:  # red minus blue in the bottom band
        band = img[-18:].astype(float)
        return float(band[..., 2].mean() - band[..., 0].mean())

    assert banner_red(frames[23]) > banner_red(frames[4]) + 40


class _Queue:
    """An extractor handing out given features in call order (the tracker sees them, not pixels)."""

    dim = 3

    def __init__(self, features: list[np.ndarray]) -> None:
        self.features = list(features)

    def __call__(self, image: np.ndarray, xywh: np.ndarray) -> np.ndarray:
        return np.array([self.features.pop(0) for _ in range(len(xywh))]).reshape(-1, 3)


def _unit(*v: float) -> np.ndarray:
    a = np.array(v, dtype=float)
    return a / np.linalg.norm(a)


def test_merges_and_uncertain_identities(tmp_path):
    import cv2

    folder = tmp_path / "img1"
    folder.mkdir()
    blank = np.full((360, 640, 3), 90, np.uint8)
    rows, feats = [], []
    a, distorted = _unit(1, 0, 0), _unit(1, 2, 0)
    for k in range(60):
        cv2.imwrite(str(folder / f"{k + 1:06d}.png"), blank)
        if k < 10:
            rows.append([k + 1, -1, 100 + 3 * k, 100, 60, 120, 1, -1, -1, -1])
            feats.append(a)
        elif k >= 40:  # returns looking different at first, then partly like itself
            rows.append([k + 1, -1, 300, 200, 60, 120, 1, -1, -1, -1])
            feats.append(distorted if k < 45 else (_unit(1, 0.3, 0) if k % 2 else distorted))
    table = MotTable.from_rows(np.array(rows, dtype=float))
    trk = DiverSort()
    res = track_video(folder, table, trk, _Queue(feats), annotate=tmp_path / "a.mp4",
                      health=HealthConfig(team_size=1))
    assert res.frames == 60 and len(res.health) == 60
    assert len(res.merges) == 1
    frame, source, target = res.merges[0]
    assert target == 1 and source != target and 40 < frame <= 56
    assert (frame, target) in {(int(f), int(i)) for f, i in res.rows[:, :2]}
    # the wrong new identity was drawn as uncertain before the merge; the old one settled before it left
    assert any(i == source for f, i in res.uncertain)
    assert all(f > 10 or i != 1 or f <= trk.config.recovery_window for f, i in res.uncertain)
    assert sum(1 for _ in read_frames(tmp_path / "a.mp4")) == 60


def test_tentative_and_new_tracks_are_uncertain(tmp_path):
    import cv2

    folder = tmp_path / "img1"
    folder.mkdir()
    for k in range(4):
        cv2.imwrite(str(folder / f"{k + 1:06d}.png"), np.zeros((100, 100, 3), np.uint8))

    class Fixed:
        """Reports a tentative track 1 and a confirmed track 2 every frame."""

        def reset(self) -> None:
            pass

        def update(self, frame):
            box = np.array([10.0, 10, 20, 20])
            return [TrackSnapshot(track_id=1, status=TrackStatus.TENTATIVE, xywh=box),
                    TrackSnapshot(track_id=2, status=TrackStatus.CONFIRMED, xywh=box + 40)]

    table = MotTable.from_rows(np.zeros((0, 10)))
    res = track_video(folder, table, Fixed(), _Queue([]), new_frames=2)
    assert res.uncertain == [(1, 1), (1, 2), (2, 1), (2, 2), (3, 1), (4, 1)]
    assert not hasattr(res, "merges") or res.merges == []
    with pytest.raises(ValueError, match="new_frames"):
        track_video(folder, table, Fixed(), _Queue([]), new_frames=0)


def test_cli_video_errors(diver_scene, tmp_path):
    root, det = diver_scene
    r = runner.invoke(app, ["track", "--video", str(root / "divers.mp4"), "-o", str(tmp_path / "o.txt")])
    assert r.exit_code == 2 and "--detections" in r.output
    r = runner.invoke(app, ["track", str(det), "-o", str(tmp_path / "o.txt"), "--annotate", str(tmp_path / "a.mp4")])
    assert r.exit_code == 2 and "only with --video" in r.output
    r = runner.invoke(app, ["track", "--video", str(tmp_path / "none.mp4"), "--detections", str(det),
                            "-o", str(tmp_path / "o.txt")])
    assert r.exit_code == 2 and "none.mp4" in r.output
    zero = tmp_path / "zero.txt"  # a zero-width box: the tracker's error named neither the file nor the line
    zero.write_text(det.read_text().split("\n", 1)[0] + "\n2,-1,10,10,0,20,0.9,-1,-1,-1\n")
    r = runner.invoke(app, ["track", "-t", "sort", "--video", str(root / "divers.mp4"), "--detections", str(zero),
                            "-o", str(tmp_path / "o.txt")])
    assert r.exit_code == 2 and f"{zero}:2: invalid box: zero or negative width" in r.output, r.output


def test_draw_banner_cuts_long_text():
    img = np.zeros((60, 120, 3), np.uint8)
    draw_banner(img, "x" * 500)
    assert img[-5:, :, 2].mean() > img[-5:, :, 0].mean() + 50 and img[:30].max() == 0


@pytest.mark.parametrize("tracker", ["diversort", "deepsort"])
def test_mot17_mini_real_pixels(tmp_path, tracker):
    seq = DATA / "mot17_mini" / "MOT17-04-FRCNN"
    if not (seq / "img1").is_dir():
        pytest.skip(f"real data not found at {seq} (see ../shared/data/README.md)")
    n_images = len(list((seq / "img1").glob("*.jpg")))
    out, ann = tmp_path / "t.txt", tmp_path / "a.mp4"
    r = runner.invoke(app, ["track", "--tracker", tracker, "--video", str(seq / "img1"), "--detections",
                            str(seq / "det" / "det.txt"), "-o", str(out), "--annotate", str(ann),
                            "--set", "n_init=1"])
    assert r.exit_code == 0, r.output
    assert sum(1 for _ in read_frames(ann)) == n_images
    health = _csv(side_file(out, "health"))
    assert len(health) == n_images and all(int(h["n_detections"]) > 0 for h in health)
    assert len(read_mot(out)) > 0
    assert make_tracker(tracker) is not None


def test_fit_video_features_links_boxes_into_chains(diver_scene):
    from lookalike.pipeline.tracking import fit_video_features
    from lookalike.vision.appearance import FeatureStats

    root, det = diver_scene
    table = read_mot(det)
    ext = fit_video_features(root / "divers.mp4", table)
    equal = FeatureStats(mean=np.zeros_like(ext.stats_.mean), scale=np.ones_like(ext.stats_.scale)).weight
    assert not np.allclose(ext.stats_.weight, equal)  # discriminant weights from the IoU chains
    feats = ext(next(read_frames(root / "divers.mp4")), table.xywh[table.frame == 1])
    assert np.allclose(np.linalg.norm(feats, axis=1), 1.0)
    with pytest.raises(ValueError, match="fewer than 2 boxes"):
        fit_video_features(root / "divers.mp4", MotTable.from_rows(np.array([[1, -1, 0, 0, 5, 5, 1, -1, -1, -1]])))
    r = runner.invoke(app, ["track", "--video", str(root / "divers.mp4"), "--detections", str(det),
                            "-o", str(root / "x.txt"), "--features", "nope"])
    assert r.exit_code == 2 and "--features" in r.output
    one = root / "one.txt"
    one.write_text("1,-1,0,0,5,5,1,-1,-1,-1\n")
    r = runner.invoke(app, ["track", "--video", str(root / "divers.mp4"), "--detections", str(one), "-t",
                            "diversort", "-o", str(root / "y.txt")])
    assert r.exit_code == 2 and "one.txt: fewer than 2 boxes" in r.output, r.output


def test_trackers_reading_no_appearance_get_no_features(diver_scene, tmp_path, monkeypatch):
    """boxtrack and sort read boxes only: `track --video` fits and computes no appearance features for them (the
    feature code is made to fail), and their rows are those of the same detections tracked as a file."""
    import lookalike.pipeline.tracking as tracking
    import lookalike.pipeline.video as video_pipeline

    def refuse(*args, **kwargs):
        raise AssertionError("appearance features computed for a tracker that reads none")

    monkeypatch.setattr(video_pipeline, "VideoFeatures", refuse)
    monkeypatch.setattr(tracking, "raw_features", refuse)
    root, det = diver_scene
    for tracker in ("boxtrack", "sort"):
        out, plain = tmp_path / f"{tracker}.txt", tmp_path / f"{tracker}-plain.txt"
        r = runner.invoke(app, ["track", "-t", tracker, "--video", str(root / "divers.mp4"), "--detections", str(det),
                                "-o", str(out)])
        assert r.exit_code == 0, r.output
        r = runner.invoke(app, ["track", "-t", tracker, str(det), "-o", str(plain)])
        assert r.exit_code == 0, r.output
        video_rows, file_rows = read_mot(out), read_mot(plain)
        assert len(video_rows) and np.array_equal(video_rows.frame, file_rows.frame)
        assert np.array_equal(video_rows.track_id, file_rows.track_id)
        assert np.allclose(video_rows.xywh, file_rows.xywh, atol=1e-3)
