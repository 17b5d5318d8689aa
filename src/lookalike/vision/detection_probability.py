"""A detector's last-stage margin → the detection probability the identifiers were trained on: a monotone
piecewise-linear map fitted by quantile mapping onto the simulator's scores."""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from lookalike._files import write_bytes

SHIPPED_PROBABILITY = Path(__file__).resolve().parent / "models_data" / "robot_detection_probability.json"


@dataclass(frozen=True)
class DetectionProbability:
    """Monotone map from last-stage margin to probability: knots ``margin`` (increasing) and ``probability``
    (non-decreasing, in [0, 1]), and ``fitted_on``, how they were fitted."""

    margin: tuple[float, ...]
    probability: tuple[float, ...]
    fitted_on: dict[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        m, p = np.asarray(self.margin, float), np.asarray(self.probability, float)
        if m.ndim != 1 or len(m) < 2 or m.shape != p.shape:
            raise ValueError(f"DetectionProbability: need two equal-length lists of at least 2 knots, got "
                             f"{m.shape} and {p.shape}")
        if not (np.isfinite(m).all() and np.isfinite(p).all()) or (np.diff(m) < 0).any() or (np.diff(p) < 0).any():
            raise ValueError("DetectionProbability: knots must be finite and non-decreasing")
        if p[0] < 0 or p[-1] > 1:
            raise ValueError(f"DetectionProbability: probabilities must be in [0, 1], got {p[0]}..{p[-1]}")

    def __call__(self, margins: np.ndarray) -> np.ndarray:
        """Probabilities ``(n,)`` of last-stage ``margins`` ``(n,)`` (linear between knots, clipped outside)."""
        return np.interp(np.asarray(margins, float), np.asarray(self.margin), np.asarray(self.probability))

    def save(self, path: str | Path) -> None:
        """Write the knots and ``fitted_on`` as JSON, through a temporary file renamed into place."""
        doc = {"margin": list(self.margin), "probability": list(self.probability), "fitted_on": self.fitted_on}
        write_bytes(Path(path), (json.dumps(doc, indent=1) + "\n").encode())

    @classmethod
    def load(cls, path: str | Path) -> DetectionProbability:
        """Read a file written by :meth:`save`; anything else raises ``ValueError`` naming ``path``."""
        try:
            doc = json.loads(Path(path).read_text())
            return cls(tuple(map(float, doc["margin"])), tuple(map(float, doc["probability"])),
                       dict(doc.get("fitted_on", {})))
        except (OSError, json.JSONDecodeError, KeyError, TypeError, ValueError) as exc:
            raise ValueError(f"{path}: not a detection-probability file ({exc})") from None


def fit_quantile_map(margins: np.ndarray, target_scores: np.ndarray, knots: int = 101,
                     fitted_on: dict[str, Any] | None = None) -> DetectionProbability:
    """The margin at quantile q of ``margins`` → the value at quantile q of ``target_scores``, at ``knots`` quantiles
    (tied margins merged, the highest probability kept)."""
    m, s = np.asarray(margins, float).ravel(), np.asarray(target_scores, float).ravel()
    if len(m) < 2 or len(s) < 2:
        raise ValueError(f"fit_quantile_map: need at least 2 margins and 2 target scores, got {len(m)}, {len(s)}")
    q = np.linspace(0.0, 1.0, int(knots))
    km, kp = np.quantile(m, q), np.clip(np.quantile(s, q), 0.0, 1.0)
    km, first = np.unique(km, return_index=True)
    last = np.append(first[1:] - 1, len(kp) - 1)
    kp = kp[last]
    if len(km) < 2:
        raise ValueError("fit_quantile_map: all margins are equal")
    return DetectionProbability(tuple(km.tolist()), tuple(kp.tolist()), dict(fitted_on or {}))


def shipped_detection_probability() -> DetectionProbability | None:
    """The map shipped beside the detector (``models_data/robot_detection_probability.json``), ``None`` if absent."""
    return DetectionProbability.load(SHIPPED_PROBABILITY) if SHIPPED_PROBABILITY.is_file() else None


__all__ = ["SHIPPED_PROBABILITY", "DetectionProbability", "fit_quantile_map", "shipped_detection_probability"]
