"""Hand-crafted appearance features: shape, invariance, discrimination, speed-free checks, real pixels."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from lookalike.vision.appearance import (
    RAW_DIM,
    FeatureExtractor,
    HandcraftedFeatures,
    crop_boxes,
    fit_stats,
    raw_features,
)

DATA = Path(__file__).resolve().parents[1].parent / "shared" / "data"


def scene(suit: tuple[int, int, int], tank: tuple[int, int, int], fins: tuple[int, int, int], gain: float = 1.0,
          seed: int = 0) -> np.ndarray:
    """A 200x200 BGR image of a crude diver on blue-green water."""
    import cv2

    rng = np.random.default_rng(seed)
    img = np.empty((200, 200, 3), np.uint8)
    img[:] = (120, 100, 40)
    img = np.clip(img + rng.normal(0, 3, img.shape), 0, 255).astype(np.uint8)
    cv2.ellipse(img, (100, 100), (25, 60), 0, 0, 360, suit, -1)
    cv2.rectangle(img, (90, 60), (110, 120), tank, -1)
    cv2.circle(img, (100, 35), 14, suit, -1)
    cv2.ellipse(img, (85, 170), (8, 20), 20, 0, 360, fins, -1)
    cv2.ellipse(img, (115, 170), (8, 20), -20, 0, 360, fins, -1)
    return np.clip(img.astype(float) * gain, 0, 255).astype(np.uint8)


BOX = np.array([[60.0, 15.0, 80.0, 180.0]])
DIVER_1 = ((30, 30, 30), (0, 200, 230), (40, 40, 40))
DIVER_2 = ((60, 40, 30), (190, 190, 190), (0, 140, 220))


def fitted() -> HandcraftedFeatures:
    raw = np.vstack([raw_features(crop_boxes(scene(*d, gain=g, seed=s), BOX, 32))
                     for d in (DIVER_1, DIVER_2) for g in (0.8, 1.0, 1.2) for s in range(3)])
    return HandcraftedFeatures(stats=fit_stats(raw))


def test_shapes_norm_and_protocol() -> None:
    ext = HandcraftedFeatures()
    assert isinstance(ext, FeatureExtractor)
    img = scene(*DIVER_1)
    feats = ext(img, np.array([[60.0, 15, 80, 180], [0, 0, 40, 40], [-50, -50, 10, 10]]))
    assert feats.shape == (3, RAW_DIM) and np.isfinite(feats).all()
    assert np.allclose(np.linalg.norm(feats, axis=1), 1.0)
    assert ext(img, np.zeros((0, 4))).shape == (0, RAW_DIM)


def test_same_crop_gives_identical_vector() -> None:
    ext = fitted()
    img = scene(*DIVER_1)
    assert np.array_equal(ext(img, BOX), ext(img.copy(), BOX))


def test_brightness_moves_features_far_less_than_another_diver() -> None:
    ext = fitted()
    base = ext(scene(*DIVER_1, seed=5), BOX)[0]
    brighter = ext(scene(*DIVER_1, gain=1.25, seed=6), BOX)[0]
    darker = ext(scene(*DIVER_1, gain=0.8, seed=7), BOX)[0]
    other = ext(scene(*DIVER_2, seed=5), BOX)[0]
    d_light = max(1 - base @ brighter, 1 - base @ darker)
    d_other = 1 - base @ other
    assert d_light < 0.5 * d_other


def test_hu_moments_match_opencv() -> None:
    import cv2

    crop = crop_boxes(scene(*DIVER_1), BOX, 32)
    raw = raw_features(crop)[0, -7:]
    from lookalike.vision.appearance import _foreground

    lab = cv2.cvtColor(crop[0].astype(np.float32) / 255, cv2.COLOR_BGR2LAB)[None].astype(float)
    hu = cv2.HuMoments(cv2.moments(_foreground(lab)[0].astype(np.uint8), True)).ravel()
    assert np.allclose(raw, np.sign(hu) * np.log10(1 + np.abs(hu) / 1e-9))


def test_running_statistics_freeze_after_warmup() -> None:
    ext = HandcraftedFeatures(warmup=4)
    img = scene(*DIVER_1)
    boxes = np.array([[60.0, 15, 80, 180], [0, 0, 60, 60], [100, 100, 90, 90]])
    ext(img, boxes)
    assert ext.stats_ is None
    ext(img, boxes)
    assert ext.stats_ is not None
    frozen = ext.stats_
    ext(scene(*DIVER_2), boxes)
    assert ext.stats_ is frozen


def test_bad_inputs_raise() -> None:
    with pytest.raises(ValueError, match="image"):
        crop_boxes(np.zeros((10, 10)), BOX, 32)
    with pytest.raises(ValueError, match="raw"):
        fit_stats(np.zeros((1, RAW_DIM)))
    with pytest.raises(ValueError, match="crop_px"):
        HandcraftedFeatures(crop_px=4)


def test_features_and_diversort_on_real_mot17_frames() -> None:
    root = DATA / "mot17_mini"
    if not root.is_dir():
        pytest.skip(f"real data not found at {root}")
    import cv2

    from lookalike.io import find_sequences, frames_from_table, read_mot
    from lookalike.trackers import make_tracker

    seqs = [s for s in find_sequences(root) if s.det_path is not None]
    assert seqs
    for seq in seqs:
        ext = HandcraftedFeatures()
        trk = make_tracker("diversort")
        images = sorted((seq.root / "img1").glob("*.jpg"))
        frames = list(frames_from_table(read_mot(seq.det_path), len(images), seq.frame_rate))
        reported = 0
        for frame, path in zip(frames, images):
            img = cv2.imread(str(path))
            det = frame.detections
            det = det.replace(feature=ext(img, det.xywh))
            tracks = trk.update(type(frame)(index=frame.index, time=frame.time, detections=det))
            assert all(0 <= t.detection_index < len(det) for t in tracks)
            reported += len(tracks)
        assert reported > 0


def test_scale_and_jitter_move_features_less_than_another_diver() -> None:
    import cv2

    ext = fitted()
    img = scene(*DIVER_1, seed=3)
    base = ext(img, BOX)[0]
    small = cv2.resize(img, (140, 140), interpolation=cv2.INTER_AREA)
    scaled = ext(small, BOX * 0.7)[0]
    shifted = ext(img, BOX + [4, -3, 6, 5])[0]
    other = ext(scene(*DIVER_2, seed=3), BOX)[0]
    assert max(1 - base @ scaled, 1 - base @ shifted) < 0.5 * (1 - base @ other)
