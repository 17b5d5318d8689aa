"""Diver SORT: each mechanism of seed B in a constructed case (features are synthetic unit vectors)."""

from __future__ import annotations

import numpy as np
import pytest

from lookalike.trackers import make_tracker
from lookalike.trackers.diversort import DiverSort
from lookalike.types import Detections, Frame

D = 8


def unit(*weights: float) -> np.ndarray:
    v = np.zeros(D)
    v[: len(weights)] = weights
    return v / np.linalg.norm(v)


A = unit(1)
B = unit(0, 1)


def frame(k: int, boxes: list[list[float]], feats: list[np.ndarray]) -> Frame:
    if not boxes:
        return Frame(index=k, time=k / 25, detections=Detections(xywh=np.zeros((0, 4)), feature=np.zeros((0, D))))
    return Frame(index=k, time=k / 25, detections=Detections(xywh=np.array(boxes, float), feature=np.array(feats)))


def ids_of(tracks) -> dict[int, int]:
    """detection index -> reported track id."""
    return {t.detection_index: t.track_id for t in tracks}


def test_iou_shortcut_keeps_track_despite_appearance_change() -> None:
    trk = DiverSort()
    box = [100, 100, 50, 100]
    for k in range(3):
        out = trk.update(frame(k, [box], [A]))
    first = ids_of(out)[0]
    before = trk.shortcut_matches
    # Same place (IoU ~0.9), completely different appearance: the shortcut still joins it.
    out = trk.update(frame(3, [[102, 101, 50, 100]], [B]))
    assert ids_of(out)[0] == first
    assert trk.shortcut_matches == before + 1


def test_without_shortcut_overlap_a_different_appearance_starts_a_new_track() -> None:
    trk = DiverSort()
    for k in range(3):
        out = trk.update(frame(k, [[100, 100, 50, 100]], [A]))
    first = ids_of(out)[0]
    trk.update(frame(3, [[115, 100, 50, 100]], [B]))  # IoU 0.54 < 0.75, appearance forbids
    assert trk.shortcut_matches == 2
    out = [trk.update(frame(k, [[115 + k, 100, 50, 100]], [B])) for k in range(4, 7)][-1]
    assert ids_of(out)[0] != first


def test_diver_absent_for_60_frames_returns_with_the_same_identity() -> None:
    rng = np.random.default_rng(0)
    trk = DiverSort()

    def noisy(f):
        return (f + 0.03 * rng.normal(size=D)) / np.linalg.norm(f + 0.03 * rng.normal(size=D))

    ids_a, ids_b = set(), set()
    for k in range(120):
        boxes, feats = [[400 + k, 200, 60, 120]], [noisy(B)]
        a_present = k < 20 or k >= 80
        if a_present:  # returns far from where it left
            x = 50 + 2 * k if k < 20 else 500 - 2 * (k - 80)
            boxes.insert(0, [x, 300, 60, 120])
            feats.insert(0, noisy(A))
        out = ids_of(trk.update(frame(k, boxes, feats)))
        if a_present and 0 in out:
            ids_a.add(out[0])
        if (1 if a_present else 0) in out:
            ids_b.add(out[1 if a_present else 0])
    assert len(ids_a) == 1 and len(ids_b) == 1 and ids_a != ids_b
    assert trk.merges == []


def test_wrong_new_identity_is_merged_back_within_15_frames() -> None:
    trk = DiverSort()
    box = [300, 200, 60, 120]
    for k in range(10):
        out = trk.update(frame(k, [[100 + 3 * k, 100, 60, 120]], [A]))
    identity = ids_of(out)[0]
    for k in range(10, 40):  # absent
        trk.update(frame(k, [], []))
    # Returns partly hidden (bubbles): far in appearance at first, then partly like itself.
    distorted = unit(1, 2)  # cosine distance 0.55 to A: above every threshold
    returned_at, merged_at = 40, None
    for k in range(40, 60):
        feat = distorted if k < 45 else (unit(1, 0.3) if k % 2 else distorted)
        out = ids_of(trk.update(frame(k, [box], [feat])))
        if out and out[0] == identity:
            merged_at = k
            break
    assert merged_at is not None and merged_at - returned_at <= 15
    assert len(trk.merges) == 1
    merge = trk.merges[0]
    assert merge.target_id == identity and merge.source_id != identity and merge.frame_index == merged_at


def test_tentative_track_that_disappears_never_becomes_an_identity() -> None:
    trk = DiverSort()
    reported: set[int] = set()
    for k in range(40):
        boxes, feats = [[100, 100, 60, 120]], [A]
        if k in (10, 11):  # a two-frame false positive far away, looking like A
            boxes.append([400, 300, 60, 120])
            feats.append(unit(1, 0.05))
        reported |= {t.track_id for t in trk.update(frame(k, boxes, feats))}
    assert len(reported) == 1
    assert trk.merges == []


def test_confirmed_tracks_persist_indefinitely() -> None:
    trk = DiverSort()
    for k in range(3):
        out = trk.update(frame(k, [[100, 100, 60, 120]], [A]))
    first = ids_of(out)[0]
    for k in range(3, 1003):
        trk.update(frame(k, [], []))
    out = [trk.update(frame(k, [[500, 50, 60, 120]], [A])) for k in range(1003, 1006)][-1]
    assert ids_of(out)[0] == first


def test_location_breaks_appearance_ties() -> None:
    trk = DiverSort()
    same = unit(1, 0, 1)
    for k in range(3):
        out = trk.update(frame(k, [[100 + 4 * k, 100, 60, 120], [300 - 4 * k, 100, 60, 120]], [same, same]))
    left, right = ids_of(out)[0], ids_of(out)[1]
    # Both identical in appearance, boxes moved beyond the IoU shortcut: location decides.
    out = ids_of(trk.update(frame(3, [[290, 100, 60, 120], [110, 100, 60, 120]], [same, same])))
    assert out[0] == right and out[1] == left


def test_missing_features_and_bad_config_raise() -> None:
    trk = DiverSort()
    with pytest.raises(ValueError, match="feature"):
        trk.update(Frame(index=0, time=0.0, detections=Detections(xywh=np.array([[0, 0, 10, 10.0]]))))
    trk.update(Frame(index=0, time=0.0))  # an empty frame without features is fine
    with pytest.raises(ValueError, match="appearance_threshold"):
        make_tracker("diversort", appearance_threshold=-1.0)


def _many_short_lived(trk: DiverSort, n_frames: int, seed: int = 0, start: int = 0) -> int:
    """From frame ``start``, every 4 frames a new diver (its own random feature) swims for 4 frames
    and leaves; returns the largest number of tracks held."""
    rng = np.random.default_rng(seed)
    feat, largest = None, 0
    for k in range(start, start + n_frames):
        if k % 4 == 0:
            feat = rng.normal(size=64)  # (64 dimensions: unrelated divers look unrelated)
            feat /= np.linalg.norm(feat)
        trk.update(frame(k, [[100 + 300 * ((k // 4) % 2), 100, 60, 120]], [feat]))
        largest = max(largest, len(trk._tracks))
    return largest


def test_long_lost_tracks_are_capped() -> None:
    """Issue 19 row: with max_age=None memory grew without bound over long runs."""
    capped = DiverSort(DiverSort.Config(max_lost=20))
    assert _many_short_lived(capped, 300) <= 20 + 2  # 75 identities
    assert len(capped._gallery) <= 20 + 2
    uncapped = DiverSort(DiverSort.Config(max_lost=None))
    assert _many_short_lived(uncapped, 500) > 100  # 125 identities kept (what happened before the cap)
    default = DiverSort()
    assert default.config.max_lost == 200
    assert _many_short_lived(default, 1000) <= 200 + 2  # 250 identities


def test_identity_persists_within_the_cap() -> None:
    a64 = np.zeros(64)
    a64[0] = 1.0
    trk = DiverSort(DiverSort.Config(max_lost=30))
    for k in range(4):
        out = trk.update(frame(k, [[100, 100, 60, 120]], [a64]))
    first = ids_of(out)[0]
    _many_short_lived(trk, 80, start=4)  # 20 other identities come and go: fewer than the cap
    out = [trk.update(frame(k, [[500, 50, 60, 120]], [a64])) for k in range(84, 87)][-1]
    assert ids_of(out)[0] == first
    _many_short_lived(trk, 200, seed=1, start=88)  # 50 more: A is the longest unseen and is forgotten
    out = [trk.update(frame(k, [[500, 50, 60, 120]], [a64])) for k in range(288, 291)][-1]
    assert ids_of(out)[0] != first
