"""Blob settings estimated from the video (vision.blob_auto)."""

import numpy as np
import pytest

from lookalike.vision.blob import BlobDetector
from lookalike.vision.blob_auto import estimate_blob_config, frame_counts, infer_target_count


def _bounce(x: float, lo: float, hi: float) -> float:
    """``x`` reflected into ``[lo, hi]`` (a target bouncing off the walls, never resting there)."""
    span = hi - lo
    u = (x - lo) % (2 * span)
    return lo + (u if u <= span else 2 * span - u)


def _arena(n_targets: int, dark: bool, radius: int, n: int = 30, seed: int = 0, clutter: bool = True):
    """Discs of ``radius`` px moving over a textured background (darker or brighter), plus 1-px speckles."""
    rng = np.random.default_rng(seed)
    base = 170 if dark else 60
    bg = (base + rng.normal(0, 3, (160, 200, 3))).clip(0, 255)
    yy, xx = np.mgrid[:160, :200]
    bg[((xx // 25) + (yy // 20)) % 2 == 0] += 20 if dark else -20  # a static floor pattern, as in a real arena
    start = rng.uniform(30, 170, n_targets)
    speed = rng.uniform(3, 6, n_targets) * rng.choice([-1, 1], n_targets)
    lanes = np.linspace(radius + 5, 160 - radius - 5, n_targets)  # one lane each: the discs never touch
    frames = []
    for t in range(n):
        img = bg.copy()
        for x0, v, cy in zip(start, speed, lanes):
            cx = _bounce(x0 + v * t, radius, 200 - radius)
            img[(xx - cx) ** 2 + (yy - cy) ** 2 <= radius**2] = 40 if dark else 220
        if clutter:
            sy, sx = rng.integers(0, 160, 5), rng.integers(0, 200, 5)
            img[sy, sx] = 255 - base
        frames.append(img.astype(np.uint8))
    return frames


@pytest.mark.parametrize("dark", [True, False])
def test_polarity_and_sizes_follow_the_video(dark: bool) -> None:
    frames = _arena(4, dark, 7)
    est = estimate_blob_config(frames)
    cfg = est.config
    assert cfg.polarity == ("dark" if dark else "bright")
    assert 0.5 * np.pi * 49 < est.target_area_px < 2 * np.pi * 49
    assert cfg.min_area_px < np.pi * 49 < cfg.max_area_px
    assert not cfg.stabilise
    assert "polarity=" in est.summary and "threshold=" in est.summary
    detector = BlobDetector(cfg).fit(frames)
    counts = [len(detector(f)) for f in frames]
    assert np.mean(np.array(counts) == 4) > 0.8  # speckles are filtered out, touching discs aside


def test_the_number_of_targets_picks_the_threshold_counting_them() -> None:
    frames = _arena(3, True, 6, seed=1)
    est = estimate_blob_config(frames, n_targets=3)
    detector = BlobDetector(est.config).fit(frames)
    assert np.mean([len(detector(f)) == 3 for f in frames]) > 0.8
    assert est.n_targets == 3
    assert est.typical_count == 3


def test_a_still_video_is_refused_and_bad_input() -> None:
    frames = _arena(2, True, 6, clutter=False)
    with pytest.raises(ValueError, match="no foreground"):
        estimate_blob_config([frames[0]] * 10)
    with pytest.raises(ValueError, match="n_targets"):
        estimate_blob_config(frames, n_targets=0)
    with pytest.raises(ValueError, match="no frames"):
        estimate_blob_config([])


def test_a_count_held_in_most_frames_is_the_number_of_targets() -> None:
    # an arena of 4: two touch (3 blobs) or one hides now and then; a false blob rarely
    counts = np.array([4] * 70 + [3] * 25 + [5] * 5)
    inferred = infer_target_count(counts)
    assert (inferred.n, inferred.closed) == (4, True) and inferred.share == 0.7
    assert "inferred 4 targets" in inferred.summary and "--targets N" in inferred.summary


def test_a_count_that_varies_over_the_video_is_no_closed_set() -> None:
    # targets come and go (a street): every count holds in a minority of the frames
    rng = np.random.default_rng(0)
    counts = np.clip(np.round(6 + 3 * np.sin(np.arange(300) / 40) + rng.normal(0, 1, 300)), 0, None)
    inferred = infer_target_count(counts)
    assert not inferred.closed and "open set" in inferred.summary
    assert infer_target_count(np.array([2] * 50 + [3] * 50)).n == 3  # a tie: the larger count
    assert not infer_target_count(np.array([2] * 50 + [3] * 50)).closed  # but no majority
    assert not infer_target_count(np.zeros(10)).closed and infer_target_count(np.zeros(0)).frames == 0


def test_frame_counts_include_frames_without_blobs() -> None:
    rows = np.array([[1, -1, 0, 0, 5, 5, 1, -1, -1, -1], [1, -1, 9, 0, 5, 5, 1, -1, -1, -1],
                     [3, -1, 0, 0, 5, 5, 1, -1, -1, -1]], dtype=float)
    assert frame_counts(rows, 4).tolist() == [2, 0, 1, 0]
    assert frame_counts(np.zeros((0, 10)), 2).tolist() == [0, 0]


def test_estimate_reports_its_steps_and_gives_the_same_settings() -> None:
    frames = _arena(3, True, 7)
    bars: list[tuple[str, int]] = []
    steps: list[int] = []

    def progress(description: str, total: int):
        bars.append((description, total))
        return lambda: steps.append(1)

    with_bar = estimate_blob_config(frames, progress=progress)
    assert len(bars) == 1 and len(steps) == bars[0][1]  # every step of the declared total, no more
    assert with_bar == estimate_blob_config(frames)


def test_image_folder_whose_frames_change_size_is_refused_naming_the_image(tmp_path):
    # numpy's "all input arrays must have the same shape" named no input
    import cv2

    from lookalike.io.video_frames import source_frames
    from lookalike.vision.blob_auto import sample_frames

    for k in range(6):
        size = (40, 50) if k < 4 else (48, 60)
        cv2.imwrite(str(tmp_path / f"{k + 1:06d}.png"), np.full((*size, 3), 200, np.uint8))
    with pytest.raises(ValueError, match=r"000005\.png is 60x48 px, the folder's first image 50x40"):
        sample_frames(tmp_path, 25)
    with pytest.raises(ValueError, match=r"000005\.png is 60x48 px, the folder's first image 50x40"):
        list(source_frames(tmp_path)[0])
