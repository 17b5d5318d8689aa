"""Training scenes for a learned diver appearance model: new divers in new conditions, from seeds 5000+ (disjoint from
the test and validation seeds)."""

from __future__ import annotations

import numpy as np

from lookalike.sim.diver_render import DiverLook
from lookalike.sim.divers import DetectorModel, DiverScenario

TRAIN_SEED0 = 5000

_TANKS = ((20, 190, 225), (175, 175, 170), (30, 200, 230), (160, 165, 175), (40, 40, 40), (30, 60, 200),
          (200, 120, 40), (60, 160, 60), (220, 220, 220), (20, 120, 230))


def _bgr(rng: np.random.Generator, low: int, high: int) -> tuple[int, int, int]:
    c = rng.integers(low, high + 1, 3)
    return int(c[0]), int(c[1]), int(c[2])


def random_looks(rng: np.random.Generator, n: int) -> tuple[DiverLook, ...]:
    """``n`` random look-alike divers (BGR colours): dark suits, varied tanks, fins, stripes and hoods."""
    looks = []
    for _ in range(n):
        suit = _bgr(rng, 20, 50)
        tank = _TANKS[int(rng.integers(len(_TANKS)))] if rng.random() < 0.6 else _bgr(rng, 20, 235)
        accent = suit if rng.random() < 0.4 else _bgr(rng, 20, 200)
        fins = _bgr(rng, 20, 40) if rng.random() < 0.6 else _bgr(rng, 20, 200)
        hood = suit if rng.random() < 0.6 else _bgr(rng, 30, 90)
        looks.append(DiverLook(suit=suit, accent=accent, tank=tank, fins=fins, hood=hood,
                               size=float(rng.uniform(0.9, 1.1))))
    return tuple(looks)


def training_scenarios(count: int = 24, frames: int = 300, seed0: int = TRAIN_SEED0) -> tuple[DiverScenario, ...]:
    """``count`` training scenarios with new divers (seeds ``seed0 .. seed0 + count - 1``)."""
    if count < 1:
        raise ValueError(f"count must be at least 1, got {count}")
    out = []
    for k in range(count):
        seed = seed0 + k
        rng = np.random.default_rng(seed)
        n = int(rng.integers(2, 5))
        pool = bool(rng.random() < 0.3)
        turbidity = float(rng.uniform(0.0, 0.15) if pool else rng.uniform(0.05, 0.75))
        out.append(DiverScenario(
            name=f"train_{k:03d}", n_divers=n, frames=frames, pool=pool, seed=seed,
            attenuation=float(rng.uniform(0.04, 0.1) if pool else rng.uniform(0.12, 0.32)),
            blur_per_m=float(rng.uniform(0.08, 0.5)), turbidity=turbidity,
            bubble_rate=float(rng.uniform(0.01, 0.09)), leave_rate=float(rng.uniform(0.003, 0.012)),
            camera_drift_px=float(rng.uniform(0.5, 3.0)), looks=random_looks(rng, n),
            detector=DetectorModel(recall=1.0, false_positives=0.0),
        ))
    return tuple(out)


__all__ = ["TRAIN_SEED0", "random_looks", "training_scenarios"]
