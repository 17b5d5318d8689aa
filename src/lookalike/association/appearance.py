"""Appearance association: cosine distances and per-track feature galleries (deep SORT's). Features are L2-normalised
rows, so the cosine distance ``1 - f·g`` lies in ``[0, 2]``."""

from __future__ import annotations

import numpy as np

from lookalike.types import Detections


def require_features(detections: Detections, tracker: str) -> np.ndarray:
    """The ``(n, d)`` feature column, or ``ValueError`` when a non-empty batch lacks it."""
    if detections.feature is None:
        if len(detections) == 0:
            return np.zeros((0, 0))
        raise ValueError(
            f"{tracker}: frame.detections.feature is missing; run an appearance extractor "
            "(lookalike.vision.appearance) before the tracker"
        )
    return detections.feature


def cosine_distance(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """``(m, k)`` cosine distances ``1 - a_i·b_j`` between L2-normalised rows ``a (m, d)`` and ``b (k, d)``."""
    a = np.asarray(a, dtype=float)
    b = np.asarray(b, dtype=float)
    if a.ndim != 2 or b.ndim != 2 or (a.size and b.size and a.shape[1] != b.shape[1]):
        raise ValueError(f"cosine_distance: expected (m, d) and (k, d), got {a.shape} and {b.shape}")
    out: np.ndarray = 1.0 - a @ b.T
    return out


class FeatureGallery:
    """The last ``budget`` features of every track (a ring buffer per track id)."""

    def __init__(self, budget: int = 100) -> None:
        if budget < 1:
            raise ValueError(f"budget must be at least 1, got {budget}")
        self.budget = budget
        self._store: dict[int, np.ndarray] = {}
        self._width: int | None = None  # every feature's length, fixed by the first one

    def check(self, features: np.ndarray) -> None:
        """``ValueError`` when ``features (k, d)`` are not as long as those seen before (the first ones fix it)."""
        if not features.size:
            return
        if self._width is None:
            self._width = features.shape[1]
        elif features.shape[1] != self._width:
            raise ValueError(f"Detections.feature: vectors of length {features.shape[1]}, but this tracker's earlier "
                             f"frames had length {self._width} (every frame's features need one length)")

    def __contains__(self, track_id: int) -> bool:
        return track_id in self._store

    def __len__(self) -> int:
        return len(self._store)

    def add(self, track_id: int, feature: np.ndarray) -> None:
        """Append one feature ``(d,)`` (or several ``(k, d)``) to a track, keeping the newest ``budget``."""
        new = np.atleast_2d(np.asarray(feature, dtype=float))
        self.check(new)
        old = self._store.get(track_id)
        stacked = new if old is None else np.vstack([old, new])
        self._store[track_id] = stacked[-self.budget :]

    def features(self, track_id: int) -> np.ndarray:
        """The stored features ``(k, d)`` of a track, oldest first (``(0, 0)`` if none)."""
        return self._store.get(track_id, np.zeros((0, 0)))

    def remove(self, track_id: int) -> None:
        """Forget a track's features."""
        self._store.pop(track_id, None)

    def merge(self, source: int, target: int) -> None:
        """Move ``source``'s features behind ``target``'s (newest kept) and forget ``source``."""
        if source in self._store:
            self.add(target, self._store.pop(source))

    def min_distance(self, track_ids: list[int] | np.ndarray, features: np.ndarray) -> np.ndarray:
        """``(k, n)``: for each track, the smallest cosine distance of each feature ``(n, d)`` to its gallery.

        A track without stored features gets ``inf``."""
        feats = np.asarray(features, dtype=float)
        out = np.full((len(track_ids), len(feats)), np.inf)
        if not len(feats):
            return out
        self.check(feats)
        for row, tid in enumerate(track_ids):
            gallery = self._store.get(int(tid))
            if gallery is not None and len(gallery):
                out[row] = cosine_distance(gallery, feats).min(axis=0)
        return out

    def pair_fraction_below(self, a: int, b: int, threshold: float) -> float:
        """Fraction of all gallery pairs (one feature of ``a``, one of ``b``) closer than ``threshold``."""
        fa, fb = self.features(a), self.features(b)
        if not len(fa) or not len(fb):
            return 0.0
        return float((cosine_distance(fa, fb) < threshold).mean())
