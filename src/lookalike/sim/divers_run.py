"""Running appearance trackers on simulated diver scenarios: render, detect, extract features, track.

Every tracker sees the same detections with the same features (as in the paper's comparison).
Feature standardisation is fitted on the validation scenarios' ground-truth crops
(:func:`fit_diver_features`), never on the scenario being scored.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from lookalike.loop import RowCollector, run
from lookalike.sim.divers import (
    VALIDATION_SCENARIOS,
    DiverScenario,
    DiverScene,
    simulate_divers,
)
from lookalike.trackers import make_tracker
from lookalike.types import Frame
from lookalike.vision.appearance import (
    FeatureExtractor,
    HandcraftedFeatures,
    crop_boxes,
    fit_stats,
    raw_features,
)


@dataclass(frozen=True, eq=False)
class PreparedScenario:
    """A scenario's ground truth ``gt (n, 9)`` and frames whose detections carry features."""

    scenario: DiverScenario
    scene: DiverScene
    frames: list[Frame]
    gt: np.ndarray


def fit_diver_features(scenarios: tuple[DiverScenario, ...] = VALIDATION_SCENARIOS, every: int = 5,
                       crop_px: int = 32) -> HandcraftedFeatures:
    """A feature extractor standardised by the within-diver spread of ground-truth crops of ``scenarios``."""
    raws, labels = [], []
    for sc in scenarios:
        scene = simulate_divers(sc)
        for k in range(0, sc.frames, every):
            rows = scene.gt[(scene.gt[:, 0] == k + 1) & (scene.gt[:, 8] > 0.5)]
            if len(rows):
                raws.append(raw_features(crop_boxes(scene.image(k), rows[:, 2:6], crop_px)))
                labels.append(rows[:, 1] + 1000 * sc.seed)
    return HandcraftedFeatures(stats=fit_stats(np.vstack(raws), np.concatenate(labels)), crop_px=crop_px)


def prepare(sc: DiverScenario, extractor: FeatureExtractor) -> PreparedScenario:
    """Simulate, render, detect and extract the features of every detection of ``sc``."""
    scene = simulate_divers(sc)
    frames = []
    for frame in scene.frames():
        det = frame.detections
        assert det.xywh is not None  # simulated detections have boxes
        feats = extractor(scene.image(frame.index), det.xywh) if len(det) else np.zeros((0, extractor.dim))
        frames.append(Frame(index=frame.index, time=frame.time, detections=det.replace(feature=feats)))
    return PreparedScenario(sc, scene, frames, scene.gt)


def run_tracker(name: str, frames: list[Frame], **params: object) -> tuple[np.ndarray, object]:
    """Run tracker ``name`` over ``frames``; MOTChallenge result rows ``(n, 10)`` and the tracker."""
    tracker = make_tracker(name, **params)
    collect = RowCollector()
    run(tracker, frames, collect)
    return collect.rows(), tracker
