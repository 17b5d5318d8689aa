"""A merged blob's pixels split into its animals, and the animals interpolated through it placed on those parts."""
from __future__ import annotations

import numpy as np
import pytest

from lookalike.trackers.offline.merges import place_in_merges
from lookalike.vision.blob_shape import PART_SIZE, blob_parts

cv2 = pytest.importorskip("cv2")


def _pixels(mask: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    ys, xs = np.nonzero(mask)
    return xs, ys


def test_bodies_that_touch_split_into_their_own_centres():
    img = np.zeros((60, 80), np.uint8)
    cv2.ellipse(img, (25, 30), (14, 5), 0, 0, 360, 255, -1)  # two bodies crossing at an angle, touching
    cv2.ellipse(img, (48, 30), (14, 5), 60, 0, 360, 255, -1)
    two = blob_parts(*_pixels(img > 0))[:4].reshape(2, 2)
    assert np.allclose(two[np.argsort(two[:, 0])], [[25, 30], [48, 30]], atol=3)
    img[:] = 0
    for cx in (15, 40, 65):  # three nose to tail
        cv2.ellipse(img, (cx, 30), (13, 5), 0, 0, 360, 255, -1)
    vec = blob_parts(*_pixels(img > 0))
    assert vec.shape == (PART_SIZE,)
    three = vec[4:].reshape(3, 2)
    assert np.allclose(three[np.argsort(three[:, 0])], [[15, 30], [40, 30], [65, 30]], atol=2)


def _two_long_bodies(size: tuple[int, int], bodies: list[tuple[tuple[int, int], int]]) -> np.ndarray:
    """The 2-part split of one blob drawn as long thin bodies (56 x 9 px) at (centre, angle in degrees), its parts
    sorted top to bottom."""
    img = np.zeros(size, np.uint8)
    for centre, angle in bodies:
        cv2.ellipse(img, centre, (28, 5), angle, 0, 360, 255, -1)
    two = blob_parts(*_pixels(img > 0))[:4].reshape(2, 2)
    return two[np.argsort(two[:, 1])]


def test_the_parts_of_a_t_follow_its_two_long_thin_bodies():
    # a body (56 x 9 px) whose end touches the middle of another, crosswise: k-means puts the crosswise body's part
    # 9 px beyond its centre (the two parts share the pixels evenly); the mixture's elongated parts follow the bodies
    two = _two_long_bodies((100, 110), [((50, 30), 0), ((50, 52), 90)])
    assert np.allclose(two, [[50, 30], [50, 52]], atol=4)


def test_two_long_thin_bodies_side_by_side_split_between_them_not_front_and_back():
    # touching along their whole length: k-means' tighter split is front and back, each part 14 px from both
    # centres; the mixture started from the split across them is the more likely one, and it finds the bodies
    two = _two_long_bodies((80, 100), [((50, 35), 0), ((50, 44), 0)])
    assert np.allclose(two, [[50, 35], [50, 44]], atol=1.5)


def test_the_detector_splits_only_blobs_much_larger_than_the_recent_ones():
    from lookalike.vision.blob import BlobConfig, BlobDetector

    background = np.full((120, 200, 3), 200, np.uint8)
    frame = background.copy()
    for cx in (20, 60, 100):
        cv2.circle(frame, (cx, 30), 8, (40, 40, 40), -1)  # three animals alone
    cv2.circle(frame, (60, 90), 8, (40, 40, 40), -1)  # two touching: one blob twice the size
    cv2.circle(frame, (75, 90), 8, (40, 40, 40), -1)
    det = BlobDetector(BlobConfig(min_area_px=20, blur_px=0, open_px=0, close_px=0), describe=True)
    det.fit(np.stack([background] * 5))
    found = det(frame)
    assert det.parts_ is not None and det.parts_.shape == (len(found), PART_SIZE)
    big = np.argmax(found.xywh[:, 2])
    assert np.isnan(np.delete(det.parts_, big, axis=0)).all()
    assert np.allclose(sorted(det.parts_[big, 0:4:2]), [60, 75], atol=2)


def test_animals_in_a_merged_blob_take_its_parts_and_keep_them_from_frame_to_frame():
    # two animals 10x4 px side by side in a merged blob (box 100..130 x 50..60); their interpolated centres lie
    # between the parts, each nearer its own part; in frame 7 the parts move a little and each animal follows its own,
    # though its interpolated centre is now nearer the other's
    rows = np.array([[5, 1, 100, 50, 10, 4], [5, 2, 118, 56, 10, 4],  # measured before the merge
                     [6, 1, 106, 51, 10, 4], [6, 2, 113, 55, 10, 4],  # interpolated inside it
                     [7, 1, 111, 54, 10, 4], [7, 2, 109, 53, 10, 4]], float)
    measured = np.array([True, True, False, False, False, False])
    merged = np.array([[6, -1, 100, 50, 30, 10, 1, -1, -1, 0], [7, -1, 100, 50, 30, 10, 1, -1, -1, 1]], float)
    shapes = np.zeros((5, 4))
    shapes[:, 0] = np.log([200.0, 200.0, 100.0, 100.0, 100.0])  # the merged blobs twice the median blob
    parts = np.full((5, PART_SIZE), np.nan)
    parts[0, :4] = [106, 52, 124, 58]
    parts[1, :4] = [123, 58, 108, 53]
    out = place_in_merges(rows, measured, merged, shapes, parts)
    centres = out[:, 2:4] + out[:, 4:6] / 2
    assert np.allclose(centres[2:], [[106, 52], [124, 58], [108, 53], [123, 58]])
    assert np.array_equal(out[:2], rows[:2]) and np.array_equal(out[:, 4:6], rows[:, 4:6])
    parts[1] = np.nan  # no split for frame 7's blob: its animals go to the box's ends as without parts
    again = place_in_merges(rows, measured, merged, shapes, parts)
    assert np.array_equal(again[4:], place_in_merges(rows, measured, merged)[4:])


def test_animals_that_cross_inside_a_merged_blob_leave_it_on_the_sides_they_come_out_on():
    # two animals 10x4 px swap sides inside a merged blob (frames 6-8) whose two parts stand still at x 105 and 125;
    # frame by frame, each would keep the part it took first; over the whole contact, the placement of the last frame
    # agrees with where each is seen right after it (frame 9)
    rows = np.array([[5, 1, 95, 50, 10, 4], [5, 2, 125, 50, 10, 4],  # measured before: 1 left, 2 right
                     *[[f, i, 0, 50, 10, 4] for f in (6, 7, 8) for i in (1, 2)],  # interpolated inside
                     [9, 1, 125, 50, 10, 4], [9, 2, 95, 50, 10, 4]], float)  # measured after: 1 right, 2 left
    for k, f in enumerate((6, 7, 8)):  # the straight line from before to after
        rows[2 + 2 * k, 2] = 95 + 30 * (f - 5) / 4
        rows[3 + 2 * k, 2] = 125 - 30 * (f - 5) / 4
    measured = np.array([True, True, *[False] * 6, True, True])
    merged = np.array([[f, -1, 100, 49, 30, 6, 1, -1, -1, k] for k, f in enumerate((6, 7, 8))], float)
    shapes = np.zeros((5, 4))
    shapes[:, 0] = np.log([200.0, 200.0, 200.0, 100.0, 100.0])  # the merged blobs twice the median blob
    parts = np.full((5, PART_SIZE), np.nan)
    parts[:3, :4] = [105, 52, 125, 52]
    out = place_in_merges(rows, measured, merged, shapes, parts)
    x = dict(zip(map(tuple, out[:, :2].astype(int).tolist()), (out[:, 2] + out[:, 4] / 2).tolist()))
    assert (x[6, 1], x[6, 2]) == (105, 125)  # as they came in
    assert (x[8, 1], x[8, 2]) == (125, 105)  # as they go out


def test_placement_over_separate_contacts_with_more_animals_than_parts():
    # three animals near one merged blob split in 2 (frame 6), then again after a frame without a merge (frame 8),
    # two of them inside its box: each frame places two of them on the two parts, the third stays where it was
    # interpolated; rows never change size, and the frame between the contacts is left alone
    rows = np.array([[f, i, 100 + 10 * i + 5 * (i == 3), 50, 10, 4] for f in (5, 6, 7, 8, 9) for i in (1, 2, 3)],
                    float)
    measured = np.isin(rows[:, 0], (5, 9))
    merged = np.array([[6, -1, 105, 49, 30, 6, 1, -1, -1, 0], [8, -1, 105, 49, 30, 6, 1, -1, -1, 1]], float)
    shapes = np.zeros((4, 4))
    shapes[:, 0] = np.log([200.0, 200.0, 100.0, 100.0])
    parts = np.full((4, PART_SIZE), np.nan)
    parts[:2, :4] = [112, 52, 128, 52]
    out = place_in_merges(rows, measured, merged, shapes, parts)
    centres = out[:, 2:4] + out[:, 4:6] / 2
    for f in (6, 8):
        at = centres[rows[:, 0] == f]
        assert sum(any(np.allclose(c, p) for p in ([112, 52], [128, 52])) for c in at) == 2
        assert len({tuple(c) for c in at}) == 3  # no two animals on one part
    assert np.array_equal(out[rows[:, 0] == 7], rows[rows[:, 0] == 7]) and np.array_equal(out[:, 4:6], rows[:, 4:6])
    assert np.array_equal(out[measured], rows[measured])


def test_the_cheapest_placements_are_those_of_the_full_list():
    # where animals crowd round many parts, the placements are ranked (Murty) instead of listed one by one: the
    # same cheapest placements, in the same order, as the full list sorted by cost
    from lookalike.trackers.offline.merges import _cheapest_placements, _placements

    rng = np.random.default_rng(3)
    for n_ids, n_parts in ((2, 2), (3, 2), (4, 6), (5, 3)):
        cost = rng.uniform(1, 50, (n_ids, n_parts))
        ok = rng.uniform(size=cost.shape) < 0.7
        listed = sorted(_placements(ok, cost), key=lambda p: sum(cost[i, j] for i, j in p))
        ranked = _cheapest_placements(np.where(ok, cost, np.inf), 10)
        assert [sorted(p) for p in ranked] == [sorted(p) for p in listed[:10]]


def test_an_animal_that_ends_the_video_in_a_merged_blob_keeps_its_identity_there():
    from lookalike.trackers.offline.merges import hold_in_merges

    # identity 1 ends at frame 5 next to a merged blob that lasts to the end (frames 6-8); identity 2 starts at frame
    # 4 out of another merged piece (frames 1-3); identity 3 ends at frame 5 far from any merged blob
    rows = np.array([[4, 2, 300, 50, 10, 4], [5, 1, 100, 50, 10, 4], [5, 2, 302, 50, 10, 4], [5, 3, 600, 50, 10, 4]],
                    float)
    ahead = np.array([[f, -1, 94 + 2 * f, 48, 30, 8] for f in (6, 7, 8)], float)
    behind = np.array([[f, -1, 290, 48, 30, 8] for f in (1, 2, 3)], float)
    held = hold_in_merges(rows, [ahead, behind])
    one, two, three = (held[held[:, 1] == i] for i in (1, 2, 3))
    assert one[:, 0].tolist() == [5, 6, 7, 8] and two[:, 0].tolist() == [1, 2, 3, 4, 5]
    assert np.allclose(one[1:, 2:4] + one[1:, 4:6] / 2, ahead[:, 2:4] + ahead[:, 4:6] / 2)  # the blob's centre
    assert np.array_equal(one[1:, 4:6], np.tile([10, 4], (3, 1)))  # its own size
    assert three[:, 0].tolist() == [5]
    assert np.array_equal(held[:, 0], np.sort(held[:, 0]))

def test_a_merged_blob_holds_as_many_animals_as_the_identities_inside_it():
    # a blob three times the median blob (the area says 3 animals) holds the two identities interpolated into it:
    # they take its split in 2 (halves at x 110 and 130), not two of its thirds
    rows = np.array([[5, 1, 95, 50, 10, 4], [5, 2, 125, 50, 10, 4],
                     [6, 1, 105, 50, 10, 4], [6, 2, 125, 50, 10, 4]], float)
    measured = np.array([True, True, False, False])
    merged = np.array([[6, -1, 100, 48, 40, 8, 1, -1, -1, 0]], float)
    shapes = np.zeros((4, 4))
    shapes[:, 0] = np.log([300.0, 100.0, 100.0, 100.0])
    parts = np.full((4, PART_SIZE), np.nan)
    parts[0, :4] = [110, 52, 130, 52]
    parts[0, 4:10] = [106, 52, 120, 52, 134, 52]
    out = place_in_merges(rows, measured, merged, shapes, parts)
    centres = out[2:, 2:4] + out[2:, 4:6] / 2
    assert np.allclose(centres, [[110, 52], [130, 52]])


def test_parts_must_match_the_shape_vectors():
    from lookalike.trackers.offline.closed_set import assign_identities

    rows = np.array([[f, 1, 10.0 + f, 10, 5, 5, 1, -1, -1, f - 1] for f in range(1, 6)])
    with pytest.raises(ValueError, match="parts"):
        assign_identities(rows, 1, 25.0, shapes=np.zeros((5, 23)), parts=np.zeros((4, PART_SIZE)))
    with pytest.raises(ValueError, match="parts"):
        assign_identities(rows, 1, 25.0, parts=np.zeros((5, PART_SIZE)))


def _parts_every_round(xs: np.ndarray, ys: np.ndarray, iterations: int = 8) -> np.ndarray:
    """blob_parts without stopping k-means at convergence: all its rounds, every time (the reference), then the
    same mixtures."""
    from lookalike.vision.blob_shape import PART_COUNTS, _mixture

    pts = np.column_stack([xs, ys]).astype(float)
    centre = pts.mean(axis=0)
    values, vectors = np.linalg.eigh(np.cov((pts - centre).T) + np.eye(2) / 12)
    out = []
    for k in PART_COUNTS:
        best, best_cost, fitted, fitted_score = np.repeat(centre[None], k, axis=0), np.inf, None, -np.inf
        for axis in (1, 0):
            centres = centre + (np.linspace(-1.0, 1.0, k) * np.sqrt(values[axis]))[:, None] * vectors[:, axis]
            for _ in range(iterations):
                label = np.argmin(((pts[:, None] - centres[None]) ** 2).sum(axis=2), axis=1)
                counts = np.bincount(label, minlength=k)
                if np.any(counts == 0):
                    break
                centres = np.column_stack([np.bincount(label, weights=pts[:, d], minlength=k) for d in (0, 1)]) \
                    / counts[:, None]
            if np.any(counts == 0):
                continue
            cost = float(((pts - centres[label]) ** 2).sum())
            if cost < best_cost:
                best, best_cost = centres, cost
            mixture = _mixture(pts, label, k, centres)
            if mixture is not None and mixture[1] > fitted_score:
                fitted, fitted_score = mixture
        best = best if fitted is None else fitted
        out.append(best[np.argsort(best @ vectors[:, 1])])
    return np.concatenate([c.ravel() for c in out])


def test_stopping_at_convergence_gives_the_same_parts():
    rng = np.random.default_rng(0)
    for _ in range(60):
        img = np.zeros((160, 160), np.uint8)
        for _ in range(int(rng.integers(1, 4))):
            centre = tuple(int(v) for v in rng.integers(40, 120, 2))
            axes = (int(rng.integers(5, 40)), int(rng.integers(3, 15)))
            cv2.ellipse(img, centre, axes, float(rng.uniform(0, 180)), 0, 360, 255, -1)
        xs, ys = _pixels(img > 0)
        assert np.array_equal(blob_parts(xs, ys), _parts_every_round(xs, ys))
