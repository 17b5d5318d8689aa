"""Tiny hand-computed sequences for CLEAR, identity and HOTA (arithmetic in the comments)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from lookalike.eval import combine, evaluate_points, evaluate_sequence
from lookalike.io import MotTable, read_mot

A = (0.0, 0.0, 10.0, 10.0)
FAR = (500.0, 500.0, 10.0, 10.0)


def table(rows: list[tuple], conf: list[float] | None = None, cls: list[int] | None = None) -> MotTable:
    """rows: (frame, id, left, top, width, height)."""
    data = np.array(rows, dtype=float).reshape(-1, 6)
    n = len(data)
    extra = np.zeros((n, 0)) if cls is None else np.array(cls, dtype=float).reshape(n, 1)
    return MotTable(data[:, 0].astype(int), data[:, 1].astype(int), data[:, 2:6],
                    np.ones(n) if conf is None else np.array(conf, float), extra)


def test_empty_tracker_output() -> None:
    # 2 objects x 2 frames = 4 gt boxes, nothing tracked: FN 4, MOTA (0-0-0)/4 = 0, ML 2,
    # IDFN 4, HOTA_FN 4 at every alpha, DetA = AssA = HOTA = 0, LocA 1 by convention.
    gt = table([(1, 1, *A), (1, 2, *FAR), (2, 1, *A), (2, 2, *FAR)])
    r = evaluate_sequence(gt, table([]), num_frames=2)
    assert (r["CLR_TP"], r["CLR_FN"], r["CLR_FP"], r["IDSW"]) == (0, 4, 0, 0)
    assert (r["MT"], r["PT"], r["ML"]) == (0, 0, 2)
    assert r["MOTA"] == 0.0 and r["MOTP"] == 0.0
    assert (r["IDTP"], r["IDFN"], r["IDFP"], r["IDF1"]) == (0, 4, 0, 0.0)
    assert r["HOTA_FN___5"] == r["HOTA_FN___95"] == 4 and r["HOTA"] == 0.0 and r["LocA"] == 1.0


def test_empty_ground_truth() -> None:
    # 3 tracker boxes, no gt: FP 3, MOTA = (0 - 3 - 0) / max(1, 0) = -3; IDFP 3; HOTA_FP 3.
    res = table([(1, 5, *A), (2, 5, *A), (2, 6, *FAR)])
    r = evaluate_sequence(table([]), res)
    assert (r["CLR_TP"], r["CLR_FN"], r["CLR_FP"]) == (0, 0, 3)
    assert r["MOTA"] == -3.0
    assert (r["IDTP"], r["IDFP"], r["IDF1"]) == (0, 3, 0.0)
    assert r["HOTA_FP___50"] == 3 and r["HOTA"] == 0.0 and r["GT_IDs"] == 0


def test_id_switch() -> None:
    # gt 1 on box A in frames 1-4; tracker 10 covers frames 1-2, tracker 20 frames 3-4 (IoU 1).
    # CLEAR: TP 4, IDSW 1 -> MOTA (4-0-1)/4 = 0.75, MOTP 1, Frag 0 (never untracked), MT 1.
    # Identity: best pairing gt1-tr10 (2 frames): IDTP 2, IDFN 2, IDFP 2, IDF1 2/(2+1+1) = 0.5.
    # HOTA: DetA 1; pairs (1,10) and (1,20) have 2 matches each, |gt1| = 4, |tr| = 2:
    #   A = 2/(4+2-2) = 0.5 for both -> AssA = (2*0.5 + 2*0.5)/4 = 0.5, HOTA = sqrt(0.5);
    #   AssRe = (2*2/4 + 2*2/4)/4 = 0.5, AssPr = (2*2/2 + 2*2/2)/4 = 1.
    gt = table([(f, 1, *A) for f in range(1, 5)])
    res = table([(1, 10, *A), (2, 10, *A), (3, 20, *A), (4, 20, *A)])
    r = evaluate_sequence(gt, res)
    assert (r["CLR_TP"], r["IDSW"], r["Frag"], r["MT"]) == (4, 1, 0, 1)
    assert r["MOTA"] == 0.75 and r["MOTP"] == 1.0
    assert (r["IDTP"], r["IDFN"], r["IDFP"]) == (2, 2, 2) and r["IDF1"] == 0.5
    assert r["DetA"] == 1.0 and r["AssA"] == pytest.approx(0.5)
    assert r["HOTA"] == pytest.approx(np.sqrt(0.5))
    assert r["AssRe"] == pytest.approx(0.5) and r["AssPr"] == pytest.approx(1.0)


def test_fragmentation_across_an_absence() -> None:
    # gt 1 on A in frames 1-5; tracker 10 on A in 1, 2, 4, 5 and a far false positive in frame 3.
    # Frame 3 is scored and gt 1 unmatched there, so tracking starts twice: Frag = 2 - 1 = 1;
    # same id afterwards: IDSW 0. TP 4, FN 1, FP 1: MOTA (4-1-0)/5 = 0.6.
    # Tracked 4/5 = 0.8 of its frames, not > 0.8: PT, not MT.
    gt = table([(f, 1, *A) for f in range(1, 6)])
    res = table([(1, 10, *A), (2, 10, *A), (3, 99, *FAR), (4, 10, *A), (5, 10, *A)])
    r = evaluate_sequence(gt, res)
    assert (r["CLR_TP"], r["CLR_FN"], r["CLR_FP"], r["IDSW"], r["Frag"]) == (4, 1, 1, 0, 1)
    assert r["MOTA"] == pytest.approx(0.6)
    assert (r["MT"], r["PT"], r["ML"]) == (0, 1, 0)


def test_frame_without_tracker_boxes_does_not_break_a_track() -> None:
    # TrackEval's convention: a frame with no tracker box at all is skipped by the continuity
    # bookkeeping, so the same gap as above without the false positive gives Frag 0.
    gt = table([(f, 1, *A) for f in range(1, 6)])
    res = table([(1, 10, *A), (2, 10, *A), (4, 10, *A), (5, 10, *A)])
    r = evaluate_sequence(gt, res)
    assert (r["CLR_TP"], r["CLR_FN"], r["CLR_FP"], r["Frag"]) == (4, 1, 0, 0)


def test_iou_exactly_at_threshold() -> None:
    # gt A = 10x10; tracker 20x10 over it: IoU = 100/200 = 0.5 exactly -> a match (>= 0.5).
    # Tracker 21x10: IoU = 100/210 < 0.5 -> no match.
    gt = table([(1, 1, *A)])
    at = evaluate_sequence(gt, table([(1, 7, 0, 0, 20, 10)]))
    below = evaluate_sequence(gt, table([(1, 7, 0, 0, 21, 10)]))
    assert (at["CLR_TP"], at["IDTP"], at["MOTP"]) == (1, 1, 0.5)
    assert (below["CLR_TP"], below["CLR_FP"], below["CLR_FN"], below["IDTP"]) == (0, 1, 1, 0)
    # HOTA counts the 0.5 match at alpha 0.05 .. 0.50 and not from 0.55 on.
    assert at["HOTA_TP___50"] == 1 and at["HOTA_TP___55"] == 0
    assert at["LocA___50"] == 0.5


def test_mot17_rules_remove_distractor_matches_and_ignored_gt() -> None:
    # gt: id 1 pedestrian on A, id 2 static person (class 7) on B, id 3 pedestrian flagged ignore
    # (conf 0) on C; the tracker has a box on each.
    B, C = (100.0, 0.0, 10.0, 10.0), (200.0, 0.0, 10.0, 10.0)
    gt = table([(1, 1, *A), (1, 2, *B), (1, 3, *C)], conf=[1, 1, 0], cls=[1, 7, 1])
    res = table([(1, 11, *A), (1, 12, *B), (1, 13, *C)])
    # MOT17: box on B removed (matched a distractor), gt 2 and 3 dropped; the box on C stays: FP.
    r17 = evaluate_sequence(gt, res, benchmark="MOT17")
    assert (r17["CLR_TP"], r17["CLR_FP"], r17["CLR_FN"], r17["Dets"], r17["GT_IDs"]) == (1, 1, 0, 2, 1)
    # MOT15: only the conf-0 row goes: TP 2 (A, B), FP 1 (C).
    r15 = evaluate_sequence(gt, res, benchmark="MOT15")
    assert (r15["CLR_TP"], r15["CLR_FP"], r15["CLR_FN"]) == (2, 1, 0)
    # custom: everything counts.
    rc = evaluate_sequence(gt, res, benchmark="custom")
    assert (rc["CLR_TP"], rc["CLR_FP"], rc["CLR_FN"]) == (3, 0, 0)


def test_points_match_within_radius() -> None:
    # radius 1 m: distance 1.0 gives similarity 1 - 1/2 = 0.5 (a match), 1.2 gives 0.4 (none).
    r = evaluate_points([1, 2], [1, 1], [[0, 0], [0, 0]], [1, 2], [4, 4], [[1.0, 0], [1.2, 0]], radius=1.0)
    assert (r["CLR_TP"], r["CLR_FN"], r["CLR_FP"]) == (1, 1, 1)
    assert r["MOTP"] == pytest.approx(0.5)
    with pytest.raises(ValueError, match="radius"):
        evaluate_points([1], [1], [[0, 0]], [1], [1], [[0, 0]], radius=0.0)


def test_combine_sums_counts_and_recomputes_ratios() -> None:
    gt = table([(f, 1, *A) for f in range(1, 5)])
    switch = evaluate_sequence(gt, table([(1, 10, *A), (2, 10, *A), (3, 20, *A), (4, 20, *A)]))
    empty = evaluate_sequence(gt, table([]))
    c = combine([switch, empty])
    # TP 4, FN 4, IDSW 1 -> MOTA (4 - 0 - 1)/8; IDTP 2, IDFN 6, IDFP 2 -> IDF1 2/(2 + 1 + 3).
    assert (c["CLR_TP"], c["CLR_FN"], c["IDSW"]) == (4, 4, 1)
    assert c["MOTA"] == pytest.approx(3 / 8) and c["IDF1"] == pytest.approx(2 / 6)
    # HOTA: TP 4 of 8 gt, 0 FP -> DetA 0.5; AssA weighted by HOTA_TP: (0.5*4 + 0*0)/4 = 0.5.
    assert c["DetA"] == pytest.approx(0.5) and c["AssA"] == pytest.approx(0.5)
    with pytest.raises(ValueError):
        combine([])


def test_bad_inputs_name_file_and_line(tmp_path: Path) -> None:
    gt_path = tmp_path / "gt.txt"
    gt_path.write_text("1,1,0,0,10,10,1,1,1\n2,1,0,0,10,10,1,1,1\n")
    dup = tmp_path / "dup.txt"
    dup.write_text("1,5,0,0,10,10,1,-1,-1,-1\n\n1,5,3,3,10,10,1,-1,-1,-1\n")
    with pytest.raises(ValueError, match=r"dup.txt:3: id 5 appears twice in frame 1"):
        evaluate_sequence(read_mot(gt_path), read_mot(dup))
    late = tmp_path / "late.txt"
    late.write_text("1,5,0,0,10,10,1,-1,-1,-1\n9,5,0,0,10,10,1,-1,-1,-1\n")
    with pytest.raises(ValueError, match=r"late.txt:2: frame 9 is beyond the sequence length 2"):
        evaluate_sequence(read_mot(gt_path), read_mot(late), num_frames=2)
    with pytest.raises(ValueError, match="benchmark"):
        evaluate_sequence(read_mot(gt_path), read_mot(late), benchmark="MOT99")
    with pytest.raises(ValueError, match="metric"):
        evaluate_sequence(read_mot(gt_path), read_mot(late), metrics=("MOTA!",))
    with pytest.raises(ValueError, match="iou_threshold"):
        evaluate_sequence(read_mot(gt_path), read_mot(late), iou_threshold=1.5)


def test_similarities_refuse_rows_of_another_width() -> None:
    from lookalike.eval import box_iou, point_similarity

    # (2, 6) holds 12 numbers: read as (3, 4) boxes it gave three rows of nonsense instead of an error.
    with pytest.raises(ValueError, match=r"gt_xywh: expected shape \(k, 4\), got \(2, 6\)"):
        box_iou(np.zeros((2, 6)), np.ones((1, 4)))
    with pytest.raises(ValueError, match="tr_xy: expected shape"):
        point_similarity(np.zeros((1, 2)), np.zeros((2, 3)), 1.0)
    with pytest.raises(ValueError, match="result_xy: expected shape"):
        evaluate_points([1, 1, 2], [1, 2, 1], [[0, 0]] * 3, [1, 1, 2], [4, 5, 4], np.zeros((2, 3)), radius=1.0)
    # one box or point as a flat row, and empty input, are still taken
    assert box_iou(np.array(A), np.array([A, FAR])).tolist() == [[1.0, 0.0]]
    assert point_similarity(np.zeros(0), np.zeros((1, 2)), 1.0).shape == (0, 1)


def test_similarities_refuse_nan_and_infinity_naming_the_row() -> None:
    """A NaN box gave a NaN IoU (and a NaN point a NaN score) silently; now a ValueError names argument and row."""
    from lookalike.eval import box_iou, point_similarity

    with pytest.raises(ValueError, match=r"tr_xywh\[1\]: NaN or infinity in \[0.0, nan, 1.0, 1.0\]"):
        box_iou(np.array([A]), np.array([A, [0, np.nan, 1, 1]]))
    with pytest.raises(ValueError, match=r"gt_xywh\[0\]: NaN or infinity"):
        box_iou(np.array([[0, 0, np.inf, 1]]), np.array([A]))
    with pytest.raises(ValueError, match=r"gt_xy\[0\]: NaN or infinity"):
        point_similarity(np.array([[np.nan, 0]]), np.zeros((1, 2)), 1.0)


def test_points_refuse_frames_and_ids_that_are_not_whole() -> None:
    # frame 1.5 was truncated to frame 1 and id 2.7 to id 2: scored as if they were those
    with pytest.raises(ValueError, match=r"gt_frame\[0\]: 1.5 is not a whole number"):
        evaluate_points([1.5], [1], [[0, 0]], [1], [1], [[0, 0]], radius=1.0)
    with pytest.raises(ValueError, match=r"result_id\[1\]: 2.7 is not a whole number"):
        evaluate_points([1], [1], [[0, 0]], [1, 1], [1, 2.7], [[0, 0], [5, 5]], radius=1.0)
    with pytest.raises(ValueError, match=r"result_frame\[0\]: nan"):
        evaluate_points([1], [1], [[0, 0]], [np.nan], [1], [[0, 0]], radius=1.0)
    # whole numbers held as floats are taken as before
    r = evaluate_points(np.array([1.0]), np.array([1.0]), [[0, 0]], [1], [1], [[0, 0]], radius=1.0)
    assert r["CLR_TP"] == 1
