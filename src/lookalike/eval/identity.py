"""Identity metrics (Ristani et al. 2016): IDF1, IDP, IDR from the one-to-one id matching maximising the frames both
are matched (similarity >= threshold)."""

from __future__ import annotations

import numpy as np

from lookalike.eval.data import Pairs, SequenceData
from lookalike.eval.matching import hungarian

COUNTS = ("IDTP", "IDFN", "IDFP")


def identity_counts(data: SequenceData, pairs: Pairs, threshold: float = 0.5) -> dict[str, float]:
    """``IDTP``, ``IDFN``, ``IDFP`` of one sequence; ``pairs`` is ``data.pairs()``."""
    linear_sum_assignment = hungarian()
    n_gt, n_tr = data.num_gt_dets, data.num_tracker_dets
    if n_gt == 0 or n_tr == 0:
        return {"IDTP": 0, "IDFN": n_gt, "IDFP": n_tr}
    ok = pairs.similarity >= threshold
    key = pairs.gt_id[ok] * data.num_tracker_ids + pairs.tracker_id[ok]
    overlap = np.bincount(key, minlength=data.num_gt_ids * data.num_tracker_ids)
    overlap = overlap.reshape(data.num_gt_ids, data.num_tracker_ids)
    rows, cols = linear_sum_assignment(overlap, maximize=True)
    idtp = int(overlap[rows, cols].sum())
    return {"IDTP": idtp, "IDFN": n_gt - idtp, "IDFP": n_tr - idtp}


def identity_final(c: dict[str, float]) -> dict[str, float]:
    """IDF1, IDR, IDP from (possibly summed) counts."""
    tp, fn, fp = c["IDTP"], c["IDFN"], c["IDFP"]
    return {
        "IDF1": tp / max(1.0, tp + 0.5 * fp + 0.5 * fn),
        "IDR": tp / max(1.0, tp + fn),
        "IDP": tp / max(1.0, tp + fp),
    }
