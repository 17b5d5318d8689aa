"""Paper-hard detections for the diver scenarios (``bench divers --detections paper``), and new draws."""

from __future__ import annotations

import dataclasses

from lookalike.sim.divers import DetectorModel, DiverScenario

#: de Langis and Sattar, Table 2: detector precision and recall per video (percent), in our scenario order.
PAPER_DETECTION: dict[str, tuple[float, float]] = {
    "ocean_pair_clear": (49.7, 38.7),
    "ocean_trio": (59.0, 35.9),
    "ocean_trio_bubbles": (64.5, 49.1),
    "ocean_four_long_absences": (62.7, 37.2),
    "ocean_four_murky": (70.7, 54.7),
    "ocean_pair_drifting_camera": (30.5, 25.0),
    "pool_pair": (81.6, 60.3),
    "pool_four_crossing": (63.2, 25.8),
}

#: Detector models reproducing :data:`PAPER_DETECTION` at IoU 0.5 on detector draw 0 (recall, false positives per
#: frame, box noise, min visibility).
PAPER_DETECTORS: dict[str, DetectorModel] = {
    "ocean_pair_clear": DetectorModel(0.405, 0.643, 0.10, 0.3),
    "ocean_trio": DetectorModel(0.424, 0.617, 0.10, 0.3),
    "ocean_trio_bubbles": DetectorModel(0.646, 0.667, 0.10, 0.3),
    "ocean_four_long_absences": DetectorModel(0.467, 0.667, 0.10, 0.3),
    "ocean_four_murky": DetectorModel(0.642, 0.787, 0.10, 0.3),
    "ocean_pair_drifting_camera": DetectorModel(0.272, 0.974, 0.10, 0.3),
    "pool_pair": DetectorModel(0.789, 0.154, 0.10, 0.3),
    "pool_four_crossing": DetectorModel(0.299, 0.327, 0.10, 0.3),
}

DETECTION_LEVELS = ("sim", "paper")


def with_detections(sc: DiverScenario, level: str) -> DiverScenario:
    """``sc`` with the detector of ``level``: ``sim`` (its own) or ``paper`` (:data:`PAPER_DETECTORS`)."""
    if level not in DETECTION_LEVELS:
        raise ValueError(f"detections: choose one of {', '.join(DETECTION_LEVELS)}, got {level!r}")
    if level == "sim":
        return sc
    if sc.name not in PAPER_DETECTORS:
        raise ValueError(f"detections paper: no paper detector for scenario {sc.name!r}; "
                         f"known: {', '.join(PAPER_DETECTORS)}")
    return dataclasses.replace(sc, detector=PAPER_DETECTORS[sc.name])


def redraw(sc: DiverScenario, seed: int) -> DiverScenario:
    """``sc`` as a new draw (scenario seed ``sc.seed + 10000 · seed``); ``seed`` 0 keeps it."""
    if seed < 0:
        raise ValueError(f"seed must be >= 0, got {seed}")
    return sc if seed == 0 else dataclasses.replace(sc, seed=sc.seed + 10000 * seed)


__all__ = ["DETECTION_LEVELS", "PAPER_DETECTION", "PAPER_DETECTORS", "redraw", "with_detections"]
