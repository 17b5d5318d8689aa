"""CLEAR MOT metrics (Bernardin & Stiefelhagen 2008) with TrackEval's conventions.

Per frame, ground truth and tracker objects are matched by the Hungarian algorithm on similarity,
only pairs with similarity >= ``threshold`` allowed, and a pair that was matched in the previous
*scored* frame (a frame with both ground truth and tracker objects) preferred over any other.
An ID switch is a ground-truth object matched to a tracker id different from its last match
(from any earlier frame); a fragment starts each time an object becomes tracked after not being
tracked in the previous scored frame. MT: tracked > 80 % of its frames, ML: < 20 %.
"""

from __future__ import annotations

import numpy as np
from scipy.optimize import linear_sum_assignment

from lookalike.eval.data import SequenceData

_EPS = np.finfo(float).eps
COUNTS = ("CLR_TP", "CLR_FN", "CLR_FP", "IDSW", "MT", "PT", "ML", "Frag", "MOTP_sum", "CLR_Frames")


def clear_counts(data: SequenceData, threshold: float = 0.5) -> dict[str, float]:
    """The summable CLEAR counts of one sequence (see :data:`COUNTS`)."""
    n_gt = data.num_gt_ids
    gt_frames = np.zeros(n_gt)
    matched_frames = np.zeros(n_gt)
    frag_starts = np.zeros(n_gt)
    last_match = np.full(n_gt, np.nan)  # tracker id last matched, any earlier frame
    prev_step = np.full(n_gt, np.nan)  # tracker id matched in the previous scored frame
    tp = fn = fp = idsw = 0
    motp_sum = 0.0
    for gt_ids, tr_ids, sim in zip(data.gt_ids, data.tracker_ids, data.similarity):
        if len(gt_ids) == 0:
            fp += len(tr_ids)
            continue
        if len(tr_ids) == 0:
            fn += len(gt_ids)
            gt_frames[gt_ids] += 1
            continue
        score = 1000 * (tr_ids[None, :] == prev_step[gt_ids][:, None]) + sim
        score[sim < threshold - _EPS] = 0
        rows, cols = linear_sum_assignment(-score)
        ok = score[rows, cols] > _EPS
        rows, cols = rows[ok], cols[ok]
        m_gt, m_tr = gt_ids[rows], tr_ids[cols]
        before = last_match[m_gt]
        idsw += int(np.sum(~np.isnan(before) & (m_tr != before)))
        gt_frames[gt_ids] += 1
        matched_frames[m_gt] += 1
        was_untracked = np.isnan(prev_step)
        last_match[m_gt] = m_tr
        prev_step[:] = np.nan
        prev_step[m_gt] = m_tr
        frag_starts += was_untracked & ~np.isnan(prev_step)
        tp += len(rows)
        fn += len(gt_ids) - len(rows)
        fp += len(tr_ids) - len(rows)
        if len(rows):
            motp_sum += float(sim[rows, cols].sum())
    present = gt_frames > 0
    ratio = matched_frames[present] / gt_frames[present]
    mt = int(np.sum(ratio > 0.8))
    pt = int(np.sum(ratio >= 0.2)) - mt
    frag = float(np.sum(frag_starts[frag_starts > 0] - 1))
    return {"CLR_TP": tp, "CLR_FN": fn, "CLR_FP": fp, "IDSW": idsw, "MT": mt, "PT": pt,
            "ML": n_gt - mt - pt, "Frag": frag, "MOTP_sum": motp_sum, "CLR_Frames": data.num_frames}


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
