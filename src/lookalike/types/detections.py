"""``Detections``: one frame's detections as a columnar batch of equal-length arrays."""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from lookalike.types._validate import as_column, reject_unknown, require_finite

_OPTIONAL = ("position", "heading", "heading_std", "feature", "label")
_EMPTY: Detections | None = None


@dataclass(frozen=True, eq=False)
class Detections:
    """A frame's detections; every array has one row per detection.

    Attributes:
        xywh: ``(n, 4)`` boxes, left/top/width/height in pixels (zeros when omitted).
        score: ``(n,)`` detector confidence, default 1.
        position: ``(n, 2)`` ground-plane position in metres (observer frame: x forward, y left), or None.
        heading: ``(n,)`` absolute visual heading in radians, or None.
        heading_std: ``(n,)`` spread of the visual heading in radians, or None.
        feature: ``(n, d)`` appearance features, or None.
        label: ``(n,)`` integer labels (agent id, -1 for false positive), or None."""

    # Always arrays after construction; None (the default) is accepted and filled in.
    xywh: np.ndarray = None  # type: ignore[assignment]
    score: np.ndarray = None  # type: ignore[assignment]
    position: np.ndarray | None = None
    heading: np.ndarray | None = None
    heading_std: np.ndarray | None = None
    feature: np.ndarray | None = None
    label: np.ndarray | None = None

    def __post_init__(self) -> None:
        if self._fast_init():
            return
        n = _infer_length(self)
        own = "Detections"
        xywh = np.zeros((n, 4)) if self.xywh is None else self.xywh
        xywh = as_column(own, "xywh", xywh, n, 4)
        require_finite(own, "xywh", xywh)
        negative = (xywh[:, 2:] < 0).any(axis=1)
        if negative.any():
            row = int(np.flatnonzero(negative)[0])
            raise ValueError(f"{own}.xywh: row {row} has a negative width or height ({xywh[row]!r})")
        score = as_column(own, "score", np.ones(n) if self.score is None else self.score, n, None)
        require_finite(own, "score", score)
        object.__setattr__(self, "xywh", xywh)
        object.__setattr__(self, "score", score)
        for name, width in (("position", 2), ("heading", None), ("heading_std", None)):
            value = getattr(self, name)
            if value is not None:
                arr = as_column(own, name, value, n, width)
                require_finite(own, name, arr)
                object.__setattr__(self, name, arr)
        if self.feature is not None:
            feat = np.asarray(self.feature, dtype=float)
            if feat.ndim != 2:
                if feat.size == 0:
                    feat = feat.reshape(0, 0)
                else:
                    raise ValueError(f"{own}.feature: expected shape (n, d), got {feat.shape}")
            if n and feat.shape == (n, 0):
                raise ValueError(f"{own}.feature: {n} rows of length 0; each detection needs a feature vector")
            feat = as_column(own, "feature", feat, n, feat.shape[1])
            require_finite(own, "feature", feat)
            object.__setattr__(self, "feature", feat)
        if self.label is not None:
            object.__setattr__(self, "label", as_column(own, "label", self.label, n, None, int))

    def _fast_init(self) -> bool:
        """The common case (float boxes and scores only) checked whole-array; False (nothing set) otherwise."""
        xywh, score = self.xywh, self.score
        if (type(xywh) is not np.ndarray or xywh.dtype != np.float64 or xywh.ndim != 2 or xywh.shape[1] != 4
                or self.position is not None or self.heading is not None or self.heading_std is not None
                or self.feature is not None or self.label is not None):
            return False
        n = xywh.shape[0]
        if score is None:
            score = np.ones(n)
        elif type(score) is np.ndarray and score.dtype == np.float64 and score.shape == (n,):
            score = score.copy()
        else:
            return False
        if n and not (math.isfinite(float(xywh.sum()) + float(score.sum())) and xywh[:, 2:].min() >= 0):
            return False
        xywh = xywh.copy()
        xywh.setflags(write=False)
        score.setflags(write=False)
        object.__setattr__(self, "xywh", xywh)
        object.__setattr__(self, "score", score)
        return True

    def __len__(self) -> int:
        return int(self.xywh.shape[0])

    @classmethod
    def empty(cls) -> Detections:
        """A batch with no detections (one shared, read-only instance)."""
        global _EMPTY
        if _EMPTY is None:
            _EMPTY = cls(xywh=np.zeros((0, 4)))
        return _EMPTY

    @classmethod
    def from_dict(cls, columns: Mapping[str, Any]) -> Detections:
        """Build from a mapping of column name to values; unknown names raise ``ValueError``."""
        reject_unknown("Detections", dict(columns), tuple(f.name for f in dataclasses.fields(cls)))
        return cls(**columns)

    def select(self, index: np.ndarray | slice | list[int]) -> Detections:
        """Rows ``index`` as a new batch (boolean mask or integer indices)."""
        columns = {f.name: getattr(self, f.name) for f in dataclasses.fields(self)}
        values: dict[str, Any] = {name: None if col is None else col[index] for name, col in columns.items()}
        return Detections(**values)

    def require_sizes(self, tracker: str) -> None:
        """``ValueError`` naming the first box without a positive width and height (a box tracker measures sizes)."""
        sized = self.xywh[:, 2:4] > 0
        if not sized.all():
            row = int(np.flatnonzero(~sized.all(axis=1))[0])
            w, h = self.xywh[row, 2:4].tolist()
            raise ValueError(f"{tracker}: Detections.xywh row {row} is {w:g} wide and {h:g} high; box trackers need "
                             "positive sizes (give points a small box)")

    def replace(self, **changes: Any) -> Detections:
        """A copy with some columns replaced (validated again)."""
        reject_unknown("Detections", changes, tuple(f.name for f in dataclasses.fields(self)))
        return dataclasses.replace(self, **changes)


def _infer_length(det: Detections) -> int:
    for name in ("xywh", "position", "score") + _OPTIONAL:
        value = getattr(det, name)
        if value is not None:
            arr = np.asarray(value)
            return int(arr.shape[0]) if arr.ndim > 0 else 0
    return 0
