from itertools import islice

import numpy as np
import pytest

from lookalike.io.video_frames import read_frames
from lookalike.vision.blob import BlobConfig, BlobDetector
from lookalike.vision.hog_features import as_bgr_image
from tests.conftest import SHARED_DATA


def _video(n=30, seed=0):
    """Two dark discs moving over a bright textured background; returns frames and true centres."""
    rng = np.random.default_rng(seed)
    bg = (200 + rng.normal(0, 3, (120, 160, 3))).clip(0, 255)
    yy, xx = np.mgrid[:120, :160]
    frames, centres = [], []
    for t in range(n):
        img = bg.copy()
        c = [(20 + 4 * t, 30), (130 - 3 * t, 90)]
        for cx, cy in c:
            img[(xx - cx) ** 2 + (yy - cy) ** 2 <= 36] = (40, 60, 50)
        frames.append(img.astype(np.uint8))
        centres.append(c)
    return frames, np.array(centres, dtype=float)


def test_median_background_finds_every_disc():
    frames, centres = _video()
    det = BlobDetector(BlobConfig(min_area_px=40, max_area_px=400)).fit(frames)
    for img, truth in zip(frames, centres):
        d = det(img)
        assert len(d) == 2
        got = d.xywh[:, :2] + d.xywh[:, 2:] / 2
        got = got[np.argsort(got[:, 0])]
        exp = truth[np.argsort(truth[:, 0])]
        np.testing.assert_allclose(got, exp, atol=1.5)
        assert (d.score == 1).all()  # a blob has no confidence of its own


def test_area_limits_and_polarity():
    frames, _ = _video()
    assert len(BlobDetector(BlobConfig(min_area_px=500)).fit(frames)(frames[5])) == 0
    assert len(BlobDetector(BlobConfig(polarity="bright", min_area_px=40)).fit(frames)(frames[5])) == 0
    assert len(BlobDetector(BlobConfig(polarity="dark", min_area_px=40)).fit(frames)(frames[5])) == 2


def test_online_models_learn_the_background():
    frames, _ = _video(30)
    for cfg in (BlobConfig(min_area_px=40, sample_every=3, history=15), BlobConfig(method="mog2", min_area_px=40)):
        det = BlobDetector(cfg)
        counts = [len(det(img)) for img in frames]
        assert counts[-1] == 2, (cfg.method, counts)
        det.reset()
        assert len(det(frames[0])) == 0  # a fresh model has no foreground in its first frame


def test_static_scene_has_no_blobs_and_grey_input_works():
    frames, _ = _video()
    det = BlobDetector(BlobConfig(min_area_px=40)).fit([frames[0]] * 5)
    grey = frames[0].mean(axis=2).astype(np.uint8)
    assert len(BlobDetector(BlobConfig(min_area_px=40)).fit([grey] * 3)(grey)) == 0
    assert len(det(frames[0])) == 0


def test_bad_input_and_config():
    with pytest.raises(ValueError, match="BlobConfig.method"):
        BlobConfig(method="knn")
    with pytest.raises(ValueError, match="min_area_px"):
        BlobConfig(min_area_px=10, max_area_px=5)
    with pytest.raises(ValueError, match="image: empty"):
        as_bgr_image(np.zeros((0, 5, 3), np.uint8))
    with pytest.raises(ValueError, match="dtype"):
        as_bgr_image(np.zeros((4, 4), bool))
    with pytest.raises(ValueError, match="shape"):
        as_bgr_image(np.zeros((4, 4, 2), np.uint8))
    assert as_bgr_image(np.ones((4, 4), np.float32)).max() == 255
    det = BlobDetector(BlobConfig()).fit([np.zeros((10, 10, 3), np.uint8)])
    with pytest.raises(ValueError, match="differs from the background"):
        det(np.zeros((12, 10, 3), np.uint8))
    with pytest.raises(ValueError, match="no frames"):
        BlobDetector().fit([])


def test_real_hexbug_clip_recall():
    video = SHARED_DATA / "hexbug" / "training035.mp4"
    if not video.exists():
        pytest.skip(f"HexBug data not found at {video.parent}")
    frames = list(islice(read_frames(video), 101))[::10]
    truth = np.loadtxt(video.with_suffix(".csv"), delimiter=",", skiprows=1)
    det = BlobDetector(BlobConfig(min_area_px=800, open_px=9, stabilise=True)).fit(frames)
    found = total = 0
    for k, img in zip(range(0, 101, 10), frames):
        pts = truth[truth[:, 1] == k][:, 3:5]
        boxes = det(img).xywh
        for x, y in pts:
            total += 1
            inside = (boxes[:, 0] - 20 <= x) & (x <= boxes[:, 0] + boxes[:, 2] + 20)
            inside &= (boxes[:, 1] - 20 <= y) & (y <= boxes[:, 1] + boxes[:, 3] + 20)
            found += bool(inside.any())
    assert total > 0 and found / total >= 0.75
