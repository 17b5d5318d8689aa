"""The ``--points`` branch of ``lookalike eval``: results scored against point ground truth (``frame, id, x, y`` per
line, pixels), matched within ``--radius`` pixels (:func:`lookalike.eval.evaluate_points`)."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

from lookalike.eval import METRICS, evaluate_points
from lookalike.io.points import read_id_points


def score_points(gt: Path, result: Path, radius: float, metrics: Sequence[str] = METRICS) -> dict[str, float]:
    """The ``metrics`` of ``result`` against the point ground truth ``gt`` within ``radius`` pixels."""
    g, r = read_id_points(gt), read_id_points(result)
    frames = int(max(g[0].max(initial=0), r[0].max(initial=0)))
    return evaluate_points(*g, *r, radius=radius, metrics=metrics, num_frames=frames)


__all__ = ["score_points"]
