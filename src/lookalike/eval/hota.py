"""HOTA (Luiten et al. 2021) over the 19 localisation thresholds alpha = 0.05, 0.10, ..., 0.95.

Per frame, objects are matched once by the Hungarian algorithm maximising
``global_alignment(gt_id, tracker_id) * similarity``; the match is then counted at every alpha
its similarity reaches. Everything after that matching is vectorised over the 19 alphas.
Results are stored flat as ``FIELD___5`` ... ``FIELD___95`` and ``FIELD___AUC`` (the mean over
alphas); ``FIELD`` alone is the same mean.
"""

from __future__ import annotations

import numpy as np
from scipy.optimize import linear_sum_assignment

from lookalike.eval.data import Pairs, SequenceData

ALPHAS = np.arange(0.05, 0.99, 0.05)  # the exact float values TrackEval compares with
LABELS = tuple(range(5, 100, 5))
_EPS = np.finfo(float).eps
COMBINED_FIELDS = ("HOTA_TP", "HOTA_FN", "HOTA_FP", "AssA", "AssRe", "AssPr", "LocA")
FINAL_FIELDS = ("HOTA", "DetA", "AssA", "DetRe", "DetPr", "AssRe", "AssPr", "LocA", "RHOTA")


def hota_arrays(data: SequenceData, pairs: Pairs) -> dict[str, np.ndarray]:
    """Per-alpha ``(19,)`` arrays of :data:`COMBINED_FIELDS` for one sequence."""
    zeros = np.zeros(len(ALPHAS))
    out = {f: zeros.copy() for f in COMBINED_FIELDS}
    n_gt, n_tr = data.num_gt_dets, data.num_tracker_dets
    if n_gt == 0 or n_tr == 0:
        out["HOTA_FN"] += n_gt if n_tr == 0 else 0
        out["HOTA_FP"] += n_tr if n_tr and n_gt == 0 else 0
        out["LocA"][:] = 1.0
        return out
    G, T = data.num_gt_ids, data.num_tracker_ids
    gt_count = np.bincount(np.concatenate(data.gt_ids), minlength=G).astype(float)
    tr_count = np.bincount(np.concatenate(data.tracker_ids), minlength=T).astype(float)
    alignment = _global_alignment(pairs, G, T, gt_count, tr_count)
    m_gt, m_tr, m_sim = [], [], []
    for gt_ids, tr_ids, sim in zip(data.gt_ids, data.tracker_ids, data.similarity):
        if len(gt_ids) == 0 or len(tr_ids) == 0:
            continue
        rows, cols = linear_sum_assignment(-(alignment[np.ix_(gt_ids, tr_ids)] * sim))
        s = sim[rows, cols]
        keep = s >= ALPHAS[0] - _EPS
        m_gt.append(gt_ids[rows[keep]])
        m_tr.append(tr_ids[cols[keep]])
        m_sim.append(s[keep])
    s = np.concatenate(m_sim) if m_sim else np.zeros(0)
    hit = s[None, :] >= ALPHAS[:, None] - _EPS  # (19, k)
    tp = hit.sum(axis=1).astype(float)
    out["HOTA_TP"] = tp
    out["HOTA_FN"] = n_gt - tp
    out["HOTA_FP"] = n_tr - tp
    out["LocA"] = np.maximum(1e-10, (hit * s).sum(axis=1)) / np.maximum(1e-10, tp)
    if len(s):
        key = np.concatenate(m_gt) * T + np.concatenate(m_tr)
        unique, inverse = np.unique(key, return_inverse=True)
        inverse = inverse.ravel()
        matches = np.stack([np.bincount(inverse, h, minlength=len(unique)) for h in hit])
        gc, tc = gt_count[unique // T], tr_count[unique % T]
        weight = np.maximum(1.0, tp)
        out["AssA"] = (matches * matches / np.maximum(1.0, gc + tc - matches)).sum(axis=1) / weight
        out["AssRe"] = (matches * matches / np.maximum(1.0, gc)).sum(axis=1) / weight
        out["AssPr"] = (matches * matches / np.maximum(1.0, tc)).sum(axis=1) / weight
    return out


def _global_alignment(pairs: Pairs, G: int, T: int, gt_count: np.ndarray, tr_count: np.ndarray) -> np.ndarray:
    sim = pairs.similarity
    row_sum = np.bincount(pairs.gt_det, sim, minlength=pairs.num_gt_dets)
    col_sum = np.bincount(pairs.tracker_det, sim, minlength=pairs.num_tracker_dets)
    denom = col_sum[pairs.tracker_det] + row_sum[pairs.gt_det] - sim
    share = np.divide(sim, denom, out=np.zeros_like(sim), where=denom > _EPS)
    potential = np.bincount(pairs.gt_id * T + pairs.tracker_id, share, minlength=G * T).reshape(G, T)
    result: np.ndarray = potential / (gt_count[:, None] + tr_count[None, :] - potential)
    return result


def hota_final(a: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
    """Add DetRe, DetPr, DetA, HOTA and RHOTA to per-alpha arrays."""
    tp, fn, fp = a["HOTA_TP"], a["HOTA_FN"], a["HOTA_FP"]
    out = dict(a)
    out["DetRe"] = tp / np.maximum(1.0, tp + fn)
    out["DetPr"] = tp / np.maximum(1.0, tp + fp)
    out["DetA"] = tp / np.maximum(1.0, tp + fn + fp)
    out["HOTA"] = np.sqrt(out["DetA"] * a["AssA"])
    out["RHOTA"] = np.sqrt(out["DetRe"] * a["AssA"])
    return out


def hota_combine(items: list[dict[str, np.ndarray]]) -> dict[str, np.ndarray]:
    """Combine per-sequence arrays: counts summed, association scores and LocA weighted by HOTA_TP."""
    out = {f: sum((x[f] for x in items), np.zeros(len(ALPHAS))) for f in ("HOTA_TP", "HOTA_FN", "HOTA_FP")}
    tp = out["HOTA_TP"]
    for f in ("AssA", "AssRe", "AssPr"):
        out[f] = sum((x[f] * x["HOTA_TP"] for x in items), np.zeros(len(ALPHAS))) / np.maximum(1.0, tp)
    loc = sum((x["LocA"] * x["HOTA_TP"] for x in items), np.zeros(len(ALPHAS)))
    out["LocA"] = np.maximum(1e-10, loc) / np.maximum(1e-10, tp)
    return out


def flatten(arrays: dict[str, np.ndarray]) -> dict[str, float]:
    """``FIELD___<alpha%>`` and ``FIELD___AUC`` entries, plus ``FIELD`` (= AUC) for the scores
    and ``HOTA(0)``, ``LocA(0)``, ``HOTALocA(0)`` at the lowest alpha."""
    flat: dict[str, float] = {}
    for field, values in arrays.items():
        for label, v in zip(LABELS, values):
            flat[f"{field}___{label}"] = float(v)
        flat[f"{field}___AUC"] = float(np.mean(values))
        if field in FINAL_FIELDS:
            flat[field] = float(np.mean(values))
    flat["HOTA(0)"] = float(arrays["HOTA"][0])
    flat["LocA(0)"] = float(arrays["LocA"][0])
    flat["HOTALocA(0)"] = float(arrays["HOTA"][0] * arrays["LocA"][0])
    return flat


def unflatten(flat: dict[str, float]) -> dict[str, np.ndarray]:
    """Per-alpha arrays of :data:`COMBINED_FIELDS` back from a flat result."""
    try:
        return {f: np.array([flat[f"{f}___{lab}"] for lab in LABELS]) for f in COMBINED_FIELDS}
    except KeyError as exc:
        raise ValueError(f"per-sequence result lacks HOTA field {exc.args[0]!r}") from None
