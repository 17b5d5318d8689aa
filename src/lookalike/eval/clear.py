"""CLEAR MOT metrics (Bernardin & Stiefelhagen 2008) with TrackEval's conventions: per frame, Hungarian matching on
similarity >= ``threshold``, preferring the previous scored frame's pairs; an ID switch is a ground-truth object matched
to another tracker id than its last match; MT > 80 % tracked, ML < 20 %."""

from __future__ import annotations

import numpy as np

from lookalike.eval.data import SequenceData
from lookalike.eval.matching import conflicted_frames, frame_bounds, hungarian, negated_matrices

_EPS = np.finfo(float).eps
COUNTS = ("CLR_TP", "CLR_FN", "CLR_FP", "IDSW", "MT", "PT", "ML", "Frag", "MOTP_sum", "CLR_Frames")


def clear_counts(data: SequenceData, threshold: float = 0.5) -> dict[str, float]:
    """The summable CLEAR counts (:data:`COUNTS`) of one sequence; frames whose pairs at ``threshold`` are one-to-one
    are matched without the Hungarian algorithm."""
    n_gt, n_frames = data.num_gt_ids, data.num_frames
    p = data.pairs()
    cand = np.flatnonzero(p.similarity >= threshold - _EPS)
    frame, gt_det, tr_det, sim = p.frame[cand], p.gt_det[cand], p.tracker_det[cand], p.similarity[cand]
    n_g, n_t = np.diff(data.gt_bounds), np.diff(data.tracker_bounds)
    scored = (n_g > 0) & (n_t > 0)
    hard = conflicted_frames(frame, gt_det, tr_det, n_frames, data.num_gt_dets, data.num_tracker_dets)
    hard |= np.bincount(frame[sim <= _EPS], minlength=n_frames) > 0  # a bonus could make such a pair count
    hard &= scored
    bounds = frame_bounds(frame, n_frames)
    easy = ~hard[frame]
    m_frame, m_gt, m_tr, m_sim = [frame[easy]], [gt_det[easy]], [tr_det[easy]], [sim[easy]]
    if hard.any():
        solved = _solve_hard_frames(data, np.flatnonzero(hard), scored, bounds, gt_det, tr_det, sim)
        for part, extra in zip((m_frame, m_gt, m_tr, m_sim), solved):
            part.append(extra)
    mf, mg, mt, ms = (np.concatenate(x) for x in (m_frame, m_gt, m_tr, m_sim))
    order = np.argsort(mf, kind="stable")
    mf, mg, mt, ms = mf[order], data.gt_id[mg[order]], data.tracker_id[mt[order]], ms[order]
    tp = len(mf)
    # ID switches and fragments, per ground-truth id in frame order.
    step = np.cumsum(scored) - 1  # index among scored frames
    by_id = np.lexsort((mf, mg))
    g_sorted, t_sorted, s_sorted = mg[by_id], mt[by_id], step[mf[by_id]]
    same = g_sorted[1:] == g_sorted[:-1]
    idsw = int(np.sum(same & (t_sorted[1:] != t_sorted[:-1])))
    starts = np.ones(tp, bool)
    starts[1:] = ~(same & (s_sorted[1:] == s_sorted[:-1] + 1))
    frag_starts = np.bincount(g_sorted[starts], minlength=n_gt)
    frag = float(np.sum(frag_starts[frag_starts > 0] - 1))
    gt_frames = np.bincount(data.gt_id, minlength=n_gt).astype(float)
    matched_frames = np.bincount(mg, minlength=n_gt).astype(float)
    present = gt_frames > 0
    ratio = matched_frames[present] / gt_frames[present]
    mt_count = int(np.sum(ratio > 0.8))
    pt = int(np.sum(ratio >= 0.2)) - mt_count
    motp_sum = 0.0
    if tp:
        frame_starts = np.flatnonzero(np.concatenate([[True], mf[1:] != mf[:-1]]))
        for v in np.add.reduceat(ms, frame_starts).tolist():
            motp_sum += v
    return {"CLR_TP": tp, "CLR_FN": data.num_gt_dets - tp, "CLR_FP": data.num_tracker_dets - tp,
            "IDSW": idsw, "MT": mt_count, "PT": pt, "ML": n_gt - mt_count - pt, "Frag": frag,
            "MOTP_sum": motp_sum, "CLR_Frames": n_frames}


def _solve_hard_frames(data: SequenceData, hard: np.ndarray, scored: np.ndarray, bounds: np.ndarray,
                       gt_det: np.ndarray, tr_det: np.ndarray,
                       sim: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Matches ``(frame, gt det, tracker det, similarity)`` of the ``hard`` frames in frame order: Hungarian on
    the thresholded similarity plus 1000 for a pair matched in the previous scored frame."""
    linear_sum_assignment = hungarian()
    n_frames = len(scored)
    is_hard = np.zeros(n_frames, bool)
    is_hard[hard] = True
    scored_frames = np.flatnonzero(scored)
    prev_of = np.full(n_frames, -1)
    prev_of[scored_frames[1:]] = scored_frames[:-1]
    next_of = np.full(n_frames, -1)
    next_of[scored_frames[:-1]] = scored_frames[1:]
    n_ids = max(data.num_tracker_ids, 1)
    id_key = data.gt_id[gt_det] * n_ids + data.tracker_id[tr_det]
    frame = np.repeat(np.arange(n_frames), np.diff(bounds))
    # Continuations from one-to-one frames, known in advance: (next scored frame, id pair) of each of
    # their pairs against (frame, id pair) of each candidate of a hard frame.
    span = max(data.num_gt_ids, 1) * n_ids
    nxt = next_of[frame]
    src = (nxt * span + id_key)[~is_hard[frame] & (nxt >= 0) & is_hard[np.maximum(nxt, 0)]]
    in_hard = is_hard[frame]
    bonus = np.zeros(len(frame), bool)
    bonus[in_hard] = np.isin(frame[in_hard] * span + id_key[in_hard], src)
    gb, tb = data.gt_bounds, data.tracker_bounds
    c_gt, c_tr = data.gt_id[gt_det], data.tracker_id[tr_det]
    local_g, local_t = gt_det - gb[frame], tr_det - tb[frame]
    planned = sim + 1000.0 * bonus
    # Every hard frame's negated score matrix with the planned bonuses; a frame after a hard
    # frame gets its bonuses from that frame's matches, written over its block before it is solved.
    shapes = np.stack([np.diff(gb)[hard], np.diff(tb)[hard]], axis=1)
    rank = np.cumsum(is_hard) - 1
    matrices = negated_matrices(shapes, rank[frame[in_hard]], local_g[in_hard], local_t[in_hard], planned[in_hard])
    prev = np.full(max(data.num_gt_ids, 1), -1)  # tracker id matched in the previous (hard) frame
    solved: dict[int, tuple[np.ndarray, np.ndarray]] = {}
    out_g, out_t, counts = [], [], []
    cuts, g_cuts, t_cuts = bounds.tolist(), gb.tolist(), tb.tolist()
    prev_list, next_list, hard_list = prev_of.tolist(), next_of.tolist(), is_hard.tolist()
    for t, cost in zip(hard.tolist(), matrices):
        a, b = cuts[t], cuts[t + 1]
        q = prev_list[t]
        if q in solved:
            q_gt, q_tr = solved.pop(q)
            prev[q_gt] = q_tr
            cost[local_g[a:b], local_t[a:b]] = -(sim[a:b] + 1000.0 * (c_tr[a:b] == prev[c_gt[a:b]]))
            prev[q_gt] = -1
        rows, cols = linear_sum_assignment(cost)
        ok = cost[rows, cols] < -_EPS
        rows, cols = rows[ok] + g_cuts[t], cols[ok] + t_cuts[t]
        nxt = next_list[t]
        if nxt >= 0 and hard_list[nxt]:
            solved[t] = (data.gt_id[rows], data.tracker_id[cols])
        out_g.append(rows)
        out_t.append(cols)
        counts.append(len(rows))
    g_all, t_all = np.concatenate(out_g), np.concatenate(out_t)
    # Similarity of each match: every match is a candidate pair (its score is positive only there).
    n_tr = max(data.num_tracker_dets, 1)
    at = np.searchsorted(gt_det * n_tr + tr_det, g_all * n_tr + t_all)
    return np.repeat(hard, counts), g_all, t_all, sim[at]


def clear_final(c: dict[str, float]) -> dict[str, float]:
    """Ratios from (possibly summed) counts: MOTA, MOTP (mean similarity of matches), MODA, ..."""
    tp, fn, fp, idsw = c["CLR_TP"], c["CLR_FN"], c["CLR_FP"], c["IDSW"]
    n_ids = c["MT"] + c["PT"] + c["ML"]
    gt_dets = max(1.0, tp + fn)
    log_idsw = np.log10(idsw) if idsw > 0 else idsw
    return {
        "MOTA": (tp - fp - idsw) / gt_dets,
        "MOTP": c["MOTP_sum"] / max(1.0, tp),
        "MODA": (tp - fp) / gt_dets,
        "CLR_Re": tp / gt_dets,
        "CLR_Pr": tp / max(1.0, tp + fp),
        "MTR": c["MT"] / max(1.0, n_ids),
        "PTR": c["PT"] / max(1.0, n_ids),
        "MLR": c["ML"] / max(1.0, n_ids),
        "sMOTA": (c["MOTP_sum"] - fp - idsw) / gt_dets,
        "CLR_F1": tp / max(1.0, tp + 0.5 * fn + 0.5 * fp),
        "FP_per_frame": fp / max(1.0, c["CLR_Frames"]),
        "MOTAL": (tp - fp - log_idsw) / gt_dets,
    }
