"""The ``--points`` branch of ``lookalike eval``: results scored against point ground truth (``frame, id, x, y`` per
line, pixels), matched within ``--radius`` pixels (:func:`lookalike.eval.evaluate_points`)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from lookalike.eval import evaluate_points
from lookalike.io.rules import not_a_file


def read_id_points(path: Path) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(frame (n,), id (n,), xy (n, 2))`` of a ``frame,id,x,y`` file, or box centres of MOTChallenge
    rows (7 or more columns: ``frame,id,left,top,width,height,score,...``)."""
    if not path.is_file():
        raise not_a_file(path)
    rows: list[list[float]] = []
    for no, line in enumerate(path.read_text().splitlines(), start=1):
        fields = [f.strip() for f in line.split(",")] if line.strip() and not line.startswith("#") else []
        if not fields:
            continue
        try:
            values = [float(f) for f in fields]
        except ValueError:
            if not rows and no == 1:
                continue  # a header
            raise ValueError(f"{path}:{no}: not a number in {line!r}") from None
        if len(values) < 4:
            raise ValueError(f"{path}:{no}: expected frame,id,x,y, got {line!r}")
        rows.append(values[:7] if len(values) >= 7 else values[:4])
    if not rows:
        return np.zeros(0, int), np.zeros(0, int), np.zeros((0, 2))
    width = min(len(r) for r in rows)
    data = np.array([r[:width] for r in rows], dtype=float)
    xy = data[:, 2:4] + data[:, 4:6] / 2 if width >= 7 else data[:, 2:4]
    return data[:, 0].astype(int), data[:, 1].astype(int), xy


def score_points(gt: Path, result: Path, radius: float) -> dict[str, float]:
    """Metrics of ``result`` against the point ground truth ``gt`` within ``radius`` pixels."""
    g, r = read_id_points(gt), read_id_points(result)
    frames = int(max(g[0].max(initial=0), r[0].max(initial=0)))
    return evaluate_points(*g, *r, radius=radius, num_frames=frames)


__all__ = ["read_id_points", "score_points"]
