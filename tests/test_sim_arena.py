"""Rendered arenas of look-alike animals: deterministic, inside the walls, individual differences that exist when on
and vanish when off, and files that read back (video frames, MOTChallenge truth, points)."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from typer.testing import CliRunner

from lookalike.cli import app
from lookalike.sim.arena import ArenaConfig, contact_events
from lookalike.sim.arena_render import simulate_arena

cv2 = pytest.importorskip("cv2")

SMALL = ArenaConfig(n_animals=4, frames=40, image_px=300, body_length_px=40.0, body_width_px=7.0)
PLAIN = dataclasses.replace(SMALL, size_spread=0.0, head_darkness=0.0, pattern_darkness=0.0, light_drift=0.0,
                            vignetting=0.0, floor_texture=0.0, blur_px=0.0, noise_level=0.0, body_bend=0.0)


def test_same_seed_same_arena_other_seed_other_arena() -> None:
    a, b, c = simulate_arena(SMALL, 3), simulate_arena(SMALL, 3), simulate_arena(SMALL, 4)
    assert np.array_equal(a.truth, b.truth) and np.array_equal(a.frame(7), b.frame(7))
    assert not np.array_equal(a.truth, c.truth)


@pytest.mark.parametrize("shape", ["round", "square"])
def test_truth_rows_and_animals_inside_the_arena(shape: str) -> None:
    cfg = dataclasses.replace(SMALL, shape=shape, frames=300)
    arena = simulate_arena(cfg, 1)
    t = arena.truth
    assert t.shape == (300 * 4, 6)
    assert np.array_equal(t[:, 0], np.repeat(np.arange(1, 301), 4))
    assert np.array_equal(t[:, 1], np.tile(np.arange(1, 5), 300))
    assert np.all(np.abs(t[:, 4]) <= np.pi)
    assert np.all((t[:, 5] >= 40 * 0.93 - 1e-9) & (t[:, 5] <= 40 * 1.07 + 1e-9))
    rel = t[:, 2:4] - cfg.image_px / 2
    reach = np.linalg.norm(rel, axis=1) if shape == "round" else np.abs(rel).max(axis=1)
    assert np.all(reach <= cfg.wall_px - t[:, 5] / 2 + 1e-6)
    boxes = arena.boxes()
    assert np.all(boxes[:, :2] >= 0) and np.all(boxes[:, :2] + boxes[:, 2:] <= cfg.image_px)
    assert np.all(boxes[:, 2:] <= 1.02 * t[:, 5:6]) and np.all(boxes[:, 2:].max(axis=1) >= 0.6 * t[:, 5])


def test_animals_move_and_touch() -> None:
    arena = simulate_arena(ArenaConfig(frames=200), 0)
    steps = np.linalg.norm(np.diff(arena.truth.reshape(200, 8, 6)[:, :, 2:4], axis=0), axis=2)
    assert 1 < np.median(steps) < 15
    assert arena.contacts > 0


def test_contacts_count_each_approach_once() -> None:
    # two animals of length 10: apart, close for two frames, apart, close again
    xs = [100.0, 5.0, 5.0, 100.0, 5.0]
    truth = np.array([[f + 1, i + 1, 0.0 if i == 0 else x, 0.0, 0.0, 10.0] for f, x in enumerate(xs) for i in (0, 1)])
    assert contact_events(truth, 2) == 2


def test_frame_is_a_grey_bgr_image_with_dark_animals() -> None:
    arena = simulate_arena(SMALL, 2)
    image = arena.frame(1)
    assert image.shape == (300, 300, 3) and image.dtype == np.uint8
    assert np.array_equal(image[:, :, 0], image[:, :, 2])
    x, y = np.round(arena.truth[0, 2:4]).astype(int)
    assert image[y, x, 0] < np.median(image) - 40  # an animal's centre is dark on the bright floor
    with pytest.raises(ValueError, match="outside"):
        arena.frame(41)


def _darkness_at(arena_cfg: ArenaConfig, seed: int = 5) -> np.ndarray:
    """Per animal of frame 1: the mean grey of its head minus that of its middle (negative: a darker head)."""
    arena = simulate_arena(arena_cfg, seed)
    grey = arena.frame(1)[:, :, 0].astype(float)
    out = []
    for _, _, cx, cy, heading, length in arena.truth[:arena_cfg.n_animals]:
        u = np.array([np.cos(heading), np.sin(heading)])
        head = np.round(np.array([cx, cy]) + 0.32 * length * u).astype(int)
        mid = np.round(np.array([cx, cy])).astype(int)
        out.append(grey[head[1], head[0]] - grey[mid[1], mid[0]])
    return np.array(out)


def test_individual_differences_exist_when_on_and_vanish_when_off() -> None:
    on = simulate_arena(SMALL, 6)
    assert np.ptp(on.traits.scale) > 0.01 and np.ptp(on.traits.head) > 0
    off = simulate_arena(PLAIN, 6)
    assert np.all(off.traits.scale == 1) and np.all(off.traits.head == 0)
    assert np.all(off.truth[:, 5] == 40) and np.all(off.bend == 0) and np.ptp(on.bend) > 0.1
    no_noise = dataclasses.replace(PLAIN, size_spread=0.07, head_darkness=0.12, pattern_darkness=0.06)
    assert np.all(_darkness_at(no_noise) < -5)  # darker heads
    assert np.all(np.abs(_darkness_at(PLAIN)) <= 1)  # one grey level over the body
    banded = simulate_arena(dataclasses.replace(PLAIN, pattern_darkness=0.2), 6)
    assert banded.frame(1).min() < simulate_arena(PLAIN, 6).frame(1).min() - 20


def test_truth_centre_is_the_silhouette_centroid_also_when_bent() -> None:
    cfg = dataclasses.replace(PLAIN, n_animals=1, body_bend=1.0, image_px=300, body_length_px=60.0, frames=60)
    arena = simulate_arena(cfg, 8)
    k = int(np.argmax(np.abs(arena.bend))) + 1
    assert abs(arena.bend[k - 1]) > 0.2
    dark = cfg.background_level - arena.frame(k)[:, :, 0].astype(float)
    ys, xs = np.mgrid[:300, :300]
    centre = np.array([(dark * xs).sum(), (dark * ys).sum()]) / dark.sum()
    assert np.linalg.norm(centre - arena.truth[k - 1, 2:4]) < 0.6  # was 1 px before the anti-aliasing inset


def test_image_conditions_off_give_a_flat_floor() -> None:
    image = simulate_arena(dataclasses.replace(PLAIN, n_animals=1), 0).frame(1)[:, :, 0]
    assert np.ptp(image[:20, :20]) == 0 and image[0, 0] == round(PLAIN.background_level)
    noisy = simulate_arena(dataclasses.replace(SMALL, n_animals=1), 0).frame(1)[:, :, 0]
    assert noisy[:20, :20].std() > 1


def test_simulate_arena_writes_a_video_and_truth_that_read_back(tmp_path) -> None:
    out = tmp_path / "a"
    result = CliRunner().invoke(app, ["simulate", "--arena", "3", "--frames", "12", "--seed", "2", "-o", str(out)])
    assert result.exit_code == 0, result.output
    assert "contacts" in result.output and "arena.avi" in result.output
    capture = cv2.VideoCapture(str(out / "arena.avi"))
    frames = []
    while True:
        ok, image = capture.read()
        if not ok:
            break
        frames.append(image)
    assert len(frames) == 12 and frames[0].shape == (800, 800, 3)
    arena = simulate_arena(dataclasses.replace(ArenaConfig(), n_animals=3, frames=12), 2)
    assert np.abs(frames[4].astype(int) - arena.frame(5).astype(int)).mean() < 3  # Motion-JPEG is near-lossless
    gt = np.loadtxt(out / "gt.txt", delimiter=",")
    assert gt.shape == (36, 10) and set(gt[:, 1]) == {1, 2, 3} and np.all(gt[:, 6] == 1)
    assert np.allclose(gt[:, 2:6], arena.boxes(), atol=1e-3)
    points = np.loadtxt(out / "points.csv", delimiter=",", skiprows=1)
    assert (out / "points.csv").read_text().startswith("frame,id,x,y\n")
    assert np.allclose(points, arena.truth[:, :4], atol=1e-3)
    several = CliRunner().invoke(app, ["simulate", "--arena", "2", "--frames", "3", "--sequences", "2", "-o",
                                       str(tmp_path / "b")])
    assert several.exit_code == 0, several.output
    assert (tmp_path / "b" / "arena-000001" / "gt.txt").is_file()
    with_bag = CliRunner().invoke(app, ["simulate", "--arena", "2", "--bag", "-o", str(tmp_path / "c")])
    assert with_bag.exit_code == 2 and "--bag" in with_bag.output


def test_config_refuses_nonsense() -> None:
    with pytest.raises(ValueError, match="shape"):
        ArenaConfig(shape="hexagon")
    with pytest.raises(ValueError, match="too small"):
        ArenaConfig(image_px=100)
