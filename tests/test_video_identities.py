"""Identities learned from the video's own blobs: shape vectors, the learned identity map and its use by the offline
closed set (issue 50)."""

from __future__ import annotations

import numpy as np
import pytest

from lookalike.trackers.offline.appearance import (
    MARGIN_CLIP,
    OUTLIER,
    SHAPE_COLUMN,
    IdentitySpace,
    cut_at_merges,
    fit_identity_space,
    look_margins,
    single_rows,
)
from lookalike.trackers.offline.closed_set import closed_set_and_look, track_closed_set
from lookalike.trackers.offline.tracklets import Tracklet
from lookalike.vision.blob_shape import SHAPE_SIZE, blob_shapes

cv2 = pytest.importorskip("cv2")


def _fish(angle: float, length: float = 50.0, head: int = 60) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Labels, stats and difference image of one dark fish-like blob (a wide head, a thin tail) turned by ``angle``."""
    img = np.zeros((160, 160), np.uint8)
    c, s = np.cos(angle), np.sin(angle)
    for t in np.linspace(-0.5, 0.5, 60):
        width = 7 * (1 - (t + 0.5) ** 1.5) + 1  # widest at the head (t = -0.5)
        x, y = 80 + t * length * c, 80 + t * length * s
        cv2.circle(img, (int(round(x)), int(round(y))), int(round(width / 2)) + 1, 255 if t > -0.3 else head, -1)
    count, labels, stats, _ = cv2.connectedComponentsWithStats((img > 0).astype(np.uint8), connectivity=8)
    assert count == 2
    return labels, stats, img.astype(np.float32)


def test_a_blob_looks_the_same_whichever_way_it_points():
    vectors = []
    for angle in np.linspace(0, 2 * np.pi, 9)[:-1]:
        labels, stats, diff = _fish(angle)
        vectors.append(blob_shapes(labels, stats, [1], diff, np.dstack([diff] * 3))[0])
    vectors = np.array(vectors)
    assert vectors.shape == (8, SHAPE_SIZE)
    spread = vectors.std(axis=0)
    labels, stats, diff = _fish(0.3, length=60)
    bigger = blob_shapes(labels, stats, [1], diff, np.dstack([diff] * 3))[0]
    assert bigger[0] - vectors[:, 0].mean() > 5 * spread[0]  # a longer animal has a larger log area
    profile = vectors[:, 7 + 8:]
    assert np.abs(profile - profile.mean(axis=0)).max() < 0.35  # the darker head stays at one end


def _two_animals(bounce: bool) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Detection rows, shape vectors and true ids of two animals that meet in the middle, merge into one blob for 6
    frames and part again: crossing over (``bounce`` False) or turning back (``bounce`` True)."""
    rng = np.random.default_rng(0)
    looks = np.array([rng.normal(0, 1, SHAPE_SIZE), rng.normal(0, 1, SHAPE_SIZE)])
    looks[:, 0] = np.log(300.0)
    rows, shapes, truth = [], [], []
    for k in range(1, 81):
        x = np.array([20.0 + 3 * k, 260.0 - 3 * k]) if k <= 40 or not bounce else \
            np.array([140.0 - 3 * (k - 40), 140.0 + 3 * (k - 40)])
        if 38 <= k <= 43:
            rows.append([k, -1, x.mean() - 15, 95, 30, 10, 1, -1, -1, -1])
            merged = looks.mean(axis=0)
            merged[0] = np.log(600.0)
            shapes.append(merged)
            truth.append(0)
            continue
        for i in range(2):
            rows.append([k, -1, x[i] - 10, 95 + rng.normal(0, 0.3), 20, 10, 1, -1, -1, -1])
            shapes.append(looks[i] + rng.normal(0, 0.1, SHAPE_SIZE) * (np.arange(SHAPE_SIZE) > 0))
            truth.append(i + 1)
    return np.array(rows, float), np.array(shapes), np.array(truth)


def _kept_apart(result: np.ndarray, rows: np.ndarray, truth: np.ndarray) -> bool:
    """Whether each result id follows one true animal through the whole sequence."""
    seen: dict[int, set[int]] = {}
    for r in result:
        same = np.flatnonzero((rows[:, 0] == r[0]) & (np.abs(rows[:, 2] - r[2]) < 1e-6) & (truth > 0))
        for k in same:
            seen.setdefault(int(r[1]), set()).add(int(truth[k]))
    return len(seen) == 2 and all(len(v) == 1 for v in seen.values())


def test_the_learned_look_keeps_two_animals_apart_when_they_turn_back_after_touching():
    rows, shapes, truth = _two_animals(bounce=True)
    plain = track_closed_set(rows, 2, 25.0)
    looked = track_closed_set(rows, 2, 25.0, shapes=shapes)
    assert not _kept_apart(plain, rows, truth)  # motion alone carries each on through the other
    assert _kept_apart(looked, rows, truth)
    assert set(np.unique(looked[:, 1])) == {1, 2} and np.all(looked[:, 7:10] == -1)


def test_the_learned_look_agrees_with_motion_when_animals_cross_over():
    rows, shapes, truth = _two_animals(bounce=False)
    assert _kept_apart(track_closed_set(rows, 2, 25.0, shapes=shapes), rows, truth)


def test_merged_blobs_are_cut_out_of_tracklets_and_concurrent_tracklets_teach_the_map():
    rows, shapes, truth = _two_animals(bounce=True)
    tracklet = np.column_stack([rows[:, :SHAPE_COLUMN], np.arange(len(rows))])
    tracklet[:, 1] = 1
    single = single_rows(tracklet, shapes)
    assert not single[truth == 0].any() and single[truth > 0].all()
    one = tracklet[(truth == 1) | (truth == 0)]
    alone, merged = cut_at_merges([Tracklet(one, 1)], shapes)
    assert len(alone) == 2 and len(merged) == 1 and merged[0].contact
    other = tracklet[truth == 2]
    space = fit_identity_space([*alone, Tracklet(other[other[:, 0] < 38], 2), Tracklet(other[other[:, 0] > 43], 2)],
                               shapes)
    assert space is not None
    look = [space.embed(shapes[t.rows[:, SHAPE_COLUMN].astype(int)]).mean(axis=0) for t in alone]
    second = space.embed(shapes[other[other[:, 0] > 43, SHAPE_COLUMN].astype(int)]).mean(axis=0)
    same, two = space.link_evidence(np.array([look[0], look[0]]), np.array([look[1], second]))
    assert same > 0 > two


def test_a_tracklet_on_its_own_animals_identity_has_a_positive_look_margin_and_a_swapped_one_a_negative():
    rows, shapes, truth = _two_animals(bounce=True)
    tracklet = np.column_stack([rows[:, :SHAPE_COLUMN], np.arange(len(rows))])
    pieces = [Tracklet(tracklet[(truth == a) & side], a) for a in (1, 2)
              for side in (tracklet[:, 0] < 38, tracklet[:, 0] > 43)]  # animal 1 before, after; animal 2 before, after
    space = fit_identity_space(pieces, shapes)
    assert space is not None
    right = look_margins(pieces, [[0, 1], [2, 3]], shapes, space)
    swapped = look_margins(pieces, [[0, 3], [2, 1]], shapes, space)
    assert np.all(right > 0) and np.all(swapped < 0) and np.all(np.abs(swapped) <= MARGIN_CLIP)
    alone = look_margins(pieces, [[0], [2, 3], [1]], shapes, space)  # nothing else on its identity: no margin
    assert np.isnan(alone[0]) and np.isnan(alone[1]) and alone[2] > 0


def test_the_closed_set_gives_the_look_margin_of_each_row_it_judged():
    rows, shapes, truth = _two_animals(bounce=True)
    result, look = closed_set_and_look(rows, 2, 25.0, shapes=shapes)
    assert look is not None and look.shape == (len(result),)
    merged = (result[:, 0] >= 38) & (result[:, 0] <= 43)
    assert np.all(look[~merged] > 0) and np.all(np.isnan(look[merged]))  # not judged inside the merged blob
    assert np.array_equal(result, track_closed_set(rows, 2, 25.0, shapes=shapes))
    assert closed_set_and_look(rows, 2, 25.0)[1] is None  # no shapes: no look


def test_link_evidence_learns_how_much_one_animals_look_changes_between_pieces():
    """Each piece of an animal looks a little different (pose, light), more than a piece's rows differ among
    themselves; the "one animal" distance is learned from the links, so same-animal links still gain and
    different-animal links still lose."""
    rng = np.random.default_rng(0)
    d, animals = 3, rng.normal(0.0, 3.0, (6, 3))
    piece = lambda a: animals[a] + rng.normal(0.0, 0.6, d)  # noqa: E731 (a piece's mean look)
    concurrent = [(piece(a), piece(b)) for a in range(6) for b in range(a + 1, 6)]
    x = np.log([np.mean((p - q) ** 2) for p, q in concurrent])
    space = IdentitySpace(np.zeros(d), np.ones(d), np.eye(d), (float(x.mean()), float(x.std())))
    pairs = [(a, a) for a in range(6) for _ in range(5)] + [(a, (a + k) % 6) for a in range(6) for k in (1, 2, 3)]
    ev = space.link_evidence(np.array([piece(a) for a, _ in pairs]), np.array([piece(b) for _, b in pairs]))
    same = np.array([a == b for a, b in pairs])
    assert (ev[same] > 0).mean() >= 0.9 and (ev[~same] < 0).mean() >= 0.9
    assert np.all(np.abs(ev) <= np.log(1 / OUTLIER) + 1e-9)


def test_proofreading_re_solves_with_the_look_and_may_name_a_merged_blob():
    from lookalike.proofread import Correction, Session

    rows, shapes, truth = _two_animals(bounce=True)
    plain = track_closed_set(rows, 2, 25.0)  # motion alone: each carried on through the other
    first = int(plain[0, 1])
    for look in (None, shapes):
        s = Session(plain, frame_rate=25.0, n_targets=2, detections=rows, shapes=look)
        s.apply(Correction("assign", first, 3 - first, 1))  # any correction re-solves the whole set
        assert _kept_apart(s.rows, rows, truth) == (look is not None)
    merged_frame = int(rows[truth == 0, 0][0])
    on_merge = int(s.rows[s.rows[:, 0] == merged_frame, 1][0])
    s.apply(Correction("assign", on_merge, 3 - on_merge, merged_frame))  # a correction on a merged blob's row
    assert set(np.unique(s.rows[:, 1])) == {1, 2}
    with pytest.raises(ValueError, match="shapes"):
        Session(plain, frame_rate=25.0, n_targets=2, shapes=shapes)


def test_animals_interpolated_through_a_merged_blob_move_to_its_ends():
    from lookalike.trackers.offline.merges import place_in_merges

    # two animals 10x4 px pass each other inside one merged blob 30x6 px (left 100..130, top 50..56): interpolated
    # both sit near its middle, in their order along x
    rows = np.array([[5, 1, 100, 50, 10, 4], [5, 2, 120, 52, 10, 4],  # measured before the merge
                     [6, 1, 109, 51, 10, 4], [6, 2, 111, 51, 10, 4],  # interpolated inside the merge
                     [7, 1, 120, 51, 10, 4]], float)  # a lone interpolated row: no second animal in its blob
    measured = np.array([True, True, False, False, False])
    merged = np.array([[6, -1, 100, 50, 30, 6], [7, -1, 100, 50, 30, 6]], float)
    out = place_in_merges(rows, measured, merged)
    centres = out[:, 2:4] + out[:, 4:6] / 2
    assert np.allclose(centres[2], [105, 53]) and np.allclose(centres[3], [125, 53])  # 5 px in from each end
    assert np.array_equal(out[[0, 1, 4]], rows[[0, 1, 4]]) and np.array_equal(out[:, 4:6], rows[:, 4:6])


def test_blobs_that_rarely_show_one_animal_get_the_online_closed_set():
    from lookalike.trackers.offline.closed_set import online_rows

    rows, shapes, _ = _two_animals(bounce=True)
    notes: list[str] = []
    kept = track_closed_set(rows, 2, 25.0, shapes=shapes, note=notes.append)
    assert not notes  # 6 merged blobs of 166: the look is learned
    varied = shapes.copy()
    varied[::3, 0] += np.log(3.0)  # a third of the blobs three times an animal's size (shadows, merges)
    fallback = track_closed_set(rows, 2, 25.0, shapes=varied, note=notes.append)
    assert len(notes) == 1 and "--online" in notes[0]
    assert np.array_equal(fallback, online_rows(rows, 25.0, reported=True, shapes=varied, max_targets=2))
    assert not np.array_equal(kept[:, :6], fallback[:, :6])


def test_nothing_to_learn_from_a_lone_animal_and_shapes_must_match_the_detections():
    rows, shapes, truth = _two_animals(bounce=True)
    one = np.column_stack([rows[truth == 1, :SHAPE_COLUMN], np.flatnonzero(truth == 1)])
    assert fit_identity_space([Tracklet(one, 1)], shapes) is None
    with pytest.raises(ValueError, match="shapes"):
        track_closed_set(rows, 2, 25.0, shapes=shapes[:-1])


def test_concurrent_pairs_and_single_rows_scale_to_long_videos_with_the_same_answers():
    from lookalike.trackers.offline.appearance import _concurrent_pairs

    rng = np.random.default_rng(1)
    for _ in range(50):
        n = int(rng.integers(0, 30))
        first = rng.integers(0, 100, n)
        last = first + rng.integers(0, 20, n)
        a, b = np.nonzero((first[:, None] <= last[None]) & (first[None] <= last[:, None]))
        assert _concurrent_pairs(first, last) == sorted((i, j) for i, j in zip(a.tolist(), b.tolist()) if i < j)
    rows = np.zeros((3000, 10))
    rows[:, 1] = rng.integers(0, 40, len(rows))
    rows[:, SHAPE_COLUMN] = np.arange(len(rows))
    shapes = np.zeros((len(rows), SHAPE_SIZE))
    shapes[:, 0] = np.log(rng.uniform(150, 500, len(rows)))
    area = np.exp(shapes[:, 0])
    expected = np.zeros(len(rows), bool)
    for i in np.unique(rows[:, 1]):
        sel = rows[:, 1] == i
        expected[sel] = (area[sel] >= 0.6 * np.median(area[sel])) & (area[sel] <= 1.5 * np.median(area[sel]))
    assert np.array_equal(single_rows(rows, shapes), expected)


def test_the_generalised_eigenproblem_is_scipys_without_scipy_linalg():
    """The identity map's ``a v = λ b v`` solved with numpy alone gives scipy.linalg.eigh's values, its vectors up to
    sign, and vectors orthonormal under ``b``; fitting the map leaves scipy.linalg unimported."""
    import subprocess
    import sys

    from scipy.linalg import eigh

    from lookalike.trackers.offline.appearance import _generalised_eigh

    rng = np.random.default_rng(4)
    for d in (2, 9, 24):
        x, y = rng.normal(size=(40, d)), rng.normal(size=(90, d))
        a, b = x.T @ x / 40, y.T @ y / 90 + 1e-3 * np.eye(d)
        (w1, v1), (w2, v2) = eigh(a, b), _generalised_eigh(a, b)
        np.testing.assert_allclose(w2, w1, atol=1e-10)
        np.testing.assert_allclose(np.abs(v2), np.abs(v1), atol=1e-8)
        np.testing.assert_allclose(v2.T @ b @ v2, np.eye(d), atol=1e-10)
    code = ("import sys, numpy as np; from lookalike.trackers.offline.appearance import _generalised_eigh; "
            "_generalised_eigh(np.eye(3), 2 * np.eye(3)); print('scipy.linalg' in sys.modules)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.strip() == "False"
