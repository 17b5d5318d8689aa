"""Scoring one sequence, from tables or in-memory arrays, and combining sequences. Values are fractions (0.73, not 73 %)
as in TrackEval; a result dict also holds the counts needed to combine it with others."""

from __future__ import annotations

from collections.abc import Iterable, Sequence

import numpy as np

from lookalike.eval import clear, hota, identity
from lookalike.eval.data import SequenceData
from lookalike.eval.prepare import MotTable, prepare_boxes, prepare_points

METRICS = ("CLEAR", "Identity", "HOTA")
COUNT_FIELDS = ("Dets", "GT_Dets", "IDs", "GT_IDs")


def _metric_names(metrics: Iterable[str]) -> tuple[str, ...]:
    names = {m.lower(): m for m in METRICS}
    chosen = []
    for m in metrics:
        if m.lower() not in names:
            raise ValueError(f"metrics: unknown metric {m!r}; choose from {', '.join(METRICS)}")
        chosen.append(names[m.lower()])
    return tuple(dict.fromkeys(chosen))


def _check_threshold(threshold: float, name: str = "iou_threshold") -> None:
    if not 0.0 < threshold <= 1.0:
        raise ValueError(f"{name} must be in (0, 1], got {threshold}")


def evaluate_data(data: SequenceData, *, threshold: float = 0.5, metrics: Sequence[str] = METRICS) -> dict[str, float]:
    """Score prepared data: ``threshold`` is the similarity a CLEAR/identity match needs."""
    _check_threshold(threshold, "threshold")
    chosen = _metric_names(metrics)
    out: dict[str, float] = {
        "Dets": data.num_tracker_dets, "GT_Dets": data.num_gt_dets,
        "IDs": data.num_tracker_ids, "GT_IDs": data.num_gt_ids,
    }
    if "HOTA" in chosen:
        out.update(hota.flatten(hota.hota_final(hota.hota_arrays(data, data.pair))))
    if "CLEAR" in chosen:
        counts = clear.clear_counts(data, threshold)
        out.update(counts)
        out.update(clear.clear_final(counts))
    if "Identity" in chosen:
        id_counts = identity.identity_counts(data, data.pair, threshold)
        out.update(id_counts)
        out.update(identity.identity_final(id_counts))
    return out


def evaluate_sequence(gt: MotTable, result: MotTable, *, iou_threshold: float = 0.5, benchmark: str = "MOT15",
                      metrics: Sequence[str] = METRICS, num_frames: int | None = None) -> dict[str, float]:
    """CLEAR, identity and HOTA of tracker boxes ``result`` against ground truth ``gt`` (anything with
    :class:`lookalike.io.MotTable`'s columns) under ``benchmark``'s rules (:mod:`lookalike.eval.prepare`), over
    ``num_frames`` frames (default: the last present): TrackEval-named fractions (MOTA, MOTP = mean IoU of matches,
    IDF1, HOTA, ``HOTA___50``, ...) and counts (CLR_TP, IDSW, IDTP, HOTA_TP___50, ...)."""
    _check_threshold(iou_threshold)
    data = prepare_boxes(gt, result, num_frames=num_frames, benchmark=benchmark)
    return evaluate_data(data, threshold=iou_threshold, metrics=metrics)


def evaluate_points(gt_frame: np.ndarray, gt_id: np.ndarray, gt_xy: np.ndarray, result_frame: np.ndarray,
                    result_id: np.ndarray, result_xy: np.ndarray, *, radius: float, metrics: Sequence[str] = METRICS,
                    num_frames: int | None = None) -> dict[str, float]:
    """The same metrics for point data: ``(n,)`` 1-based frames and ids, ``(n, 2)`` positions (pixels or metres).
    Objects match within ``radius`` (same unit); the similarity is ``max(0, 1 - d / (2 * radius))`` so MOTP and LocA are
    mean scores, and HOTA's alphas sweep distances from 1.9 to 0.1 times ``radius``."""
    data = prepare_points(gt_frame, gt_id, gt_xy, result_frame, result_id, result_xy,
                          radius=radius, num_frames=num_frames)
    return evaluate_data(data, threshold=0.5, metrics=metrics)


def combine(per_sequence: list[dict[str, float]]) -> dict[str, float]:
    """Combine per-sequence results as TrackEval does: counts summed, HOTA's association scores and LocA weighted by
    HOTA_TP per alpha, ratios recomputed."""
    if not per_sequence:
        raise ValueError("per_sequence: nothing to combine")
    first = per_sequence[0]
    out: dict[str, float] = {}
    for f in COUNT_FIELDS:
        if f in first:
            if any(f not in r for r in per_sequence):
                raise ValueError(f"per_sequence: a result lacks {f!r}")
            out[f] = sum(r[f] for r in per_sequence)
    if "HOTA_TP___5" in first:
        out.update(hota.flatten(hota.hota_final(hota.hota_combine([hota.unflatten(r) for r in per_sequence]))))
    for counts, final in ((clear.COUNTS, clear.clear_final), (identity.COUNTS, identity.identity_final)):
        if counts[0] in first:
            try:
                summed = {f: sum(r[f] for r in per_sequence) for f in counts}
            except KeyError as exc:
                raise ValueError(f"per_sequence: a result lacks {exc.args[0]!r}") from None
            out.update(summed)
            out.update(final(summed))
    return out
