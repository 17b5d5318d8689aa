"""HOTA (Luiten et al. 2021) over the 19 thresholds alpha = 0.05, ..., 0.95: one Hungarian matching per frame on
``global_alignment * similarity``, counted at every alpha its similarity reaches. Stored as ``FIELD___5`` ...
``FIELD___95`` and ``FIELD___AUC`` (= ``FIELD``, the mean over alphas)."""

from __future__ import annotations

import numpy as np

from lookalike.eval.data import Pairs, SequenceData
from lookalike.eval.matching import conflicted_frames, negated_matrices, solve_matrices

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
    gt_count = np.bincount(data.gt_id, minlength=G).astype(float)
    tr_count = np.bincount(data.tracker_id, minlength=T).astype(float)
    alignment = _global_alignment(pairs, G, T, gt_count, tr_count)
    m_gt, m_tr, s = _match_frames(data, pairs, alignment)
    keep = s >= ALPHAS[0] - _EPS
    m_gt, m_tr, s = m_gt[keep], m_tr[keep], s[keep]
    # Each match counts at the alphas its similarity reaches: the first `level` ones.
    n_a = len(ALPHAS)
    level = np.searchsorted(ALPHAS - _EPS, s, side="right")
    tp = _at_least(np.bincount(level, minlength=n_a + 1)).astype(float)
    out["HOTA_TP"] = tp
    out["HOTA_FN"] = n_gt - tp
    out["HOTA_FP"] = n_tr - tp
    loc = _at_least(np.bincount(level, s, minlength=n_a + 1))
    out["LocA"] = np.maximum(1e-10, loc) / np.maximum(1e-10, tp)
    if len(s):
        unique, inverse = np.unique(m_gt * T + m_tr, return_inverse=True)
        per_level = np.bincount(inverse.ravel() * (n_a + 1) + level, minlength=len(unique) * (n_a + 1))
        matches = _at_least(per_level.reshape(len(unique), n_a + 1).T).astype(float)  # (19, pairs)
        gc, tc = gt_count[unique // T], tr_count[unique % T]
        weight = np.maximum(1.0, tp)
        out["AssA"] = (matches * matches / np.maximum(1.0, gc + tc - matches)).sum(axis=1) / weight
        out["AssRe"] = (matches * matches / np.maximum(1.0, gc)).sum(axis=1) / weight
        out["AssPr"] = (matches * matches / np.maximum(1.0, tc)).sum(axis=1) / weight
    return out


def _at_least(per_level: np.ndarray) -> np.ndarray:
    """From totals per level ``0 .. A`` (first axis), the totals over levels above each alpha ``(A, ...)``."""
    result: np.ndarray = np.cumsum(per_level[::-1], axis=0)[::-1][1:]
    return result


def _match_frames(data: SequenceData, pairs: Pairs,
                  alignment: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Per frame, the Hungarian matching maximising ``alignment * similarity``: matched ``(gt id, tracker id,
    similarity)`` in frame order, rows ascending within a frame (pairs of zero similarity included)."""
    n_frames = data.num_frames
    frame, gt_det, tr_det = pairs.frame, pairs.gt_det, pairs.tracker_det
    score = alignment[pairs.gt_id, pairs.tracker_id] * pairs.similarity
    hard = conflicted_frames(frame, gt_det, tr_det, n_frames, pairs.num_gt_dets, pairs.num_tracker_dets)
    # One-to-one frames: every pair is matched. Others: the Hungarian algorithm on the dense frame matrix.
    easy = ~hard[frame]
    hard_frames = np.flatnonzero(hard)
    gb, tb = data.gt_bounds, data.tracker_bounds
    shapes = np.stack([np.diff(gb)[hard_frames], np.diff(tb)[hard_frames]], axis=1)
    f = frame[~easy]
    rows, cols, counts = solve_matrices(negated_matrices(shapes, (np.cumsum(hard) - 1)[f], gt_det[~easy] - gb[f],
                                                         tr_det[~easy] - tb[f], score[~easy]))
    mf = np.concatenate([frame[easy], np.repeat(hard_frames, counts)])
    mg = np.concatenate([gt_det[easy], rows + np.repeat(gb[hard_frames], counts)])
    mt = np.concatenate([tr_det[easy], cols + np.repeat(tb[hard_frames], counts)])
    order = np.argsort(mf, kind="stable")
    mg, mt = mg[order], mt[order]
    # Similarity of each match: 0 unless it is a listed pair.
    n_tr = max(pairs.num_tracker_dets, 1)
    keys = gt_det * n_tr + tr_det
    want = mg * n_tr + mt
    at = np.minimum(np.searchsorted(keys, want), max(len(keys) - 1, 0))
    found = keys[at] == want if len(keys) else np.zeros(len(want), bool)
    s = np.where(found, pairs.similarity[at] if len(keys) else 0.0, 0.0)
    return data.gt_id[mg], data.tracker_id[mt], s


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
