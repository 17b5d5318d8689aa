"""Deep SORT style tracker: confirmation, appearance re-identification, IoU fallback, deletion."""

from __future__ import annotations

import numpy as np
import pytest

from lookalike.association.appearance import FeatureGallery, cosine_distance
from lookalike.association.stages import cascade, run_plan
from lookalike.trackers import make_tracker
from lookalike.trackers.deepsort import DeepSort, xyah_to_xywh, xywh_to_xyah
from lookalike.types import Detections, Frame

D = 6
A = np.eye(D)[0]
B = np.eye(D)[1]


def frame(k: int, boxes: list[list[float]], feats: list[np.ndarray]) -> Frame:
    xywh = np.array(boxes, float).reshape(-1, 4)
    feature = np.array(feats).reshape(len(xywh), D)
    return Frame(index=k, time=k / 25, detections=Detections(xywh=xywh, feature=feature))


def by_det(tracks) -> dict[int, int]:
    return {t.detection_index: t.track_id for t in tracks}


def test_box_conversion_round_trip() -> None:
    xywh = np.array([[10.0, 20.0, 30.0, 60.0], [0.0, 0.0, 5.0, 1.0]])
    assert np.allclose(xyah_to_xywh(xywh_to_xyah(xywh)), xywh)


def test_confirmed_after_three_hits_and_reidentified_after_occlusion() -> None:
    trk = DeepSort()
    seen: list[dict[int, int]] = []
    for k in range(40):
        boxes = [[100 + 2 * k, 100, 50, 100]]
        feats = [A]
        if not 15 <= k < 25:  # B hidden for 10 frames
            boxes.append([400 - 2 * k, 120, 50, 100])
            feats.append(B)
        seen.append(by_det(trk.update(frame(k, boxes, feats))))
    assert seen[0] == {} and seen[1] == {} and len(seen[2]) == 2
    a_ids = {s[0] for s in seen[2:]}
    b_ids = {s[1] for k, s in enumerate(seen[2:], start=2) if 1 in s}
    assert len(a_ids) == 1 and len(b_ids) == 1 and a_ids != b_ids


def test_appearance_swap_is_refused() -> None:
    trk = DeepSort()
    for k in range(5):
        out = by_det(trk.update(frame(k, [[100, 100, 50, 100], [400, 100, 50, 100]], [A, B])))
    # Both vanish for two frames, then come back at their places: appearance (gated) decides.
    trk.update(frame(5, [], []))
    trk.update(frame(6, [], []))
    again = by_det(trk.update(frame(7, [[100, 100, 50, 100], [400, 100, 50, 100]], [A, B])))
    assert again == out


def test_tentative_track_deleted_at_first_miss_and_confirmed_track_after_max_age() -> None:
    trk = DeepSort(DeepSort.Config(max_age=5))
    trk.update(frame(0, [[10, 10, 20, 40]], [A]))
    trk.update(frame(1, [], []))
    for k in range(2, 5):
        out = trk.update(frame(k, [[10, 10, 20, 40]], [A]))
    assert by_det(out)[0] == 2  # track 1 was deleted at its first miss
    for k in range(5, 12):
        trk.update(frame(k, [], []))
    out = [trk.update(frame(k, [[10, 10, 20, 40]], [A])) for k in range(12, 15)][-1]
    assert by_det(out)[0] == 3


def test_gallery_and_cascade() -> None:
    g = FeatureGallery(budget=3)
    for i in range(5):
        g.add(7, np.eye(D)[i])
    assert g.features(7).shape == (3, D)
    dist = g.min_distance([7, 8], np.eye(D)[[0, 4]])
    assert dist[0, 0] == pytest.approx(1.0) and dist[0, 1] == pytest.approx(0.0) and np.isinf(dist[1]).all()
    g.add(9, np.eye(D)[0])
    g.merge(9, 7)
    assert 9 not in g and g.pair_fraction_below(7, 7, 0.5) == pytest.approx(1 / 3)
    assert np.allclose(cosine_distance(np.eye(2), np.eye(2)), 1 - np.eye(2))
    # Level 1 tracks choose first even when an older track is cheaper.
    cost = np.array([[0.3, 0.9], [0.1, 0.2]])
    stages = cascade(np.array([1, 2]), 3, np.ones(2, bool), np.ones(2, bool), lambda r, c: cost[np.ix_(r, c)], 0.5)
    assert run_plan(stages, 2, 2).pairs.tolist() == [[0, 0], [1, 1]]


def test_missing_features_raise() -> None:
    with pytest.raises(ValueError, match="feature"):
        make_tracker("deepsort").update(Frame(index=0, time=0.0, detections=Detections(xywh=np.ones((1, 4)))))
    with pytest.raises(ValueError, match="max_cosine_distance"):
        make_tracker("deepsort", max_cosine_distance=-0.1)
