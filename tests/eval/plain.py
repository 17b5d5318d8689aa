"""The plain one-frame-at-a-time scoring (the implementation before the sparse, vectorised one), kept
as an oracle: per frame a dense similarity matrix, the Hungarian algorithm on every frame.

``plain_scores(gt, result, ...)`` returns the same keys as :func:`lookalike.eval.evaluate_sequence`.
"""

from __future__ import annotations

import numpy as np
from scipy.optimize import linear_sum_assignment

from lookalike.eval import clear, hota, identity
from lookalike.eval.data import SequenceData
from lookalike.eval.prepare import _DISTRACTORS, _VALID_CLASSES, _bounds, _num_frames, _relabel
from lookalike.eval.similarity import box_iou

_EPS = np.finfo(float).eps
Frames = tuple[list[np.ndarray], list[np.ndarray], list[np.ndarray]]


def plain_prepare(gt, result, num_frames: int | None = None, benchmark: str = "MOT15") -> tuple[Frames, int, int]:
    n = _num_frames(gt, result, num_frames)
    distractors = _DISTRACTORS.get(benchmark)
    if distractors is not None:
        gt_class = gt.extra[:, 0].astype(int)
        assert np.isin(gt_class, _VALID_CLASSES).all()
        keep_gt = (gt.conf != 0) & (gt_class == 1)
    elif benchmark == "MOT15":
        gt_class, keep_gt = None, gt.conf != 0
    else:
        gt_class, keep_gt = None, np.ones(len(gt), bool)
    g_order, g_bounds = _bounds(gt.frame, n)
    r_order, r_bounds = _bounds(result.frame, n)
    gt_ids, tr_ids, sims = [], [], []
    for t in range(n):
        g = g_order[g_bounds[t] : g_bounds[t + 1]]
        r = r_order[r_bounds[t] : r_bounds[t + 1]]
        sim = box_iou(gt.xywh[g], result.xywh[r])
        if distractors is not None and gt_class is not None and len(g) and len(r):
            score = sim.copy()
            score[score < 0.5 - _EPS] = 0.0
            rows, cols = linear_sum_assignment(-score)
            ok = score[rows, cols] > _EPS
            rows, cols = rows[ok], cols[ok]
            drop = cols[np.isin(gt_class[g][rows], distractors)]
            if len(drop):
                keep_r = np.ones(len(r), bool)
                keep_r[drop] = False
                r, sim = r[keep_r], sim[:, keep_r]
        k = keep_gt[g]
        gt_ids.append(gt.track_id[g[k]])
        tr_ids.append(result.track_id[r])
        sims.append(sim[k])
    gt_rel, n_gt = _relabel(gt_ids)
    tr_rel, n_tr = _relabel(tr_ids)
    return (gt_rel, tr_rel, sims), n_gt, n_tr


def plain_clear(frames: Frames, n_gt: int, threshold: float = 0.5) -> dict[str, float]:
    gt_frames = np.zeros(n_gt)
    matched_frames = np.zeros(n_gt)
    frag_starts = np.zeros(n_gt)
    last_match = np.full(n_gt, np.nan)
    prev_step = np.full(n_gt, np.nan)
    tp = fn = fp = idsw = 0
    motp_sum = 0.0
    for gt_ids, tr_ids, sim in zip(*frames):
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
            "ML": n_gt - mt - pt, "Frag": frag, "MOTP_sum": motp_sum, "CLR_Frames": len(frames[0])}


def plain_hota(frames: Frames, n_gt: int, n_tr: int) -> dict[str, np.ndarray]:
    gts, trs, sims = frames
    data = SequenceData.from_frames(gts, trs, sims, n_gt, n_tr)
    alphas = hota.ALPHAS
    out = {f: np.zeros(len(alphas)) for f in hota.COMBINED_FIELDS}
    n_gt_dets, n_tr_dets = data.num_gt_dets, data.num_tracker_dets
    if n_gt_dets == 0 or n_tr_dets == 0:
        out["HOTA_FN"] += n_gt_dets if n_tr_dets == 0 else 0
        out["HOTA_FP"] += n_tr_dets if n_tr_dets and n_gt_dets == 0 else 0
        out["LocA"][:] = 1.0
        return out
    gt_count = np.bincount(np.concatenate(gts), minlength=n_gt).astype(float)
    tr_count = np.bincount(np.concatenate(trs), minlength=n_tr).astype(float)
    alignment = hota._global_alignment(data.pairs(), n_gt, n_tr, gt_count, tr_count)
    m_gt, m_tr, m_sim = [], [], []
    for gt_ids, tr_ids, sim in zip(gts, trs, sims):
        if len(gt_ids) == 0 or len(tr_ids) == 0:
            continue
        rows, cols = linear_sum_assignment(-(alignment[np.ix_(gt_ids, tr_ids)] * sim))
        s = sim[rows, cols]
        keep = s >= alphas[0] - _EPS
        m_gt.append(gt_ids[rows[keep]])
        m_tr.append(tr_ids[cols[keep]])
        m_sim.append(s[keep])
    s = np.concatenate(m_sim) if m_sim else np.zeros(0)
    hit = s[None, :] >= alphas[:, None] - _EPS
    tp = hit.sum(axis=1).astype(float)
    out["HOTA_TP"], out["HOTA_FN"], out["HOTA_FP"] = tp, n_gt_dets - tp, n_tr_dets - tp
    out["LocA"] = np.maximum(1e-10, (hit * s).sum(axis=1)) / np.maximum(1e-10, tp)
    if len(s):
        key = np.concatenate(m_gt) * n_tr + np.concatenate(m_tr)
        unique, inverse = np.unique(key, return_inverse=True)
        matches = np.stack([np.bincount(inverse.ravel(), h, minlength=len(unique)) for h in hit])
        gc, tc = gt_count[unique // n_tr], tr_count[unique % n_tr]
        weight = np.maximum(1.0, tp)
        out["AssA"] = (matches * matches / np.maximum(1.0, gc + tc - matches)).sum(axis=1) / weight
        out["AssRe"] = (matches * matches / np.maximum(1.0, gc)).sum(axis=1) / weight
        out["AssPr"] = (matches * matches / np.maximum(1.0, tc)).sum(axis=1) / weight
    return out


def plain_scores(gt, result, *, num_frames: int | None = None, benchmark: str = "MOT15",
                 threshold: float = 0.5) -> dict[str, float]:
    frames, n_gt, n_tr = plain_prepare(gt, result, num_frames, benchmark)
    data = SequenceData.from_frames(*frames, n_gt, n_tr)
    out: dict[str, float] = {"Dets": data.num_tracker_dets, "GT_Dets": data.num_gt_dets, "IDs": n_tr, "GT_IDs": n_gt}
    out.update(hota.flatten(hota.hota_final(plain_hota(frames, n_gt, n_tr))))
    counts = plain_clear(frames, n_gt, threshold)
    out.update(counts)
    out.update(clear.clear_final(counts))
    id_counts = identity.identity_counts(data, data.pairs(), threshold)
    out.update(id_counts)
    out.update(identity.identity_final(id_counts))
    return out
