"""Running appearance trackers on simulated diver scenarios: render, detect, extract features, track."""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path

import numpy as np

from lookalike.loop import RowCollector, run
from lookalike.sim.divers import (
    VALIDATION_SCENARIOS,
    DetectorModel,
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


#: Cosine thresholds of the trackers' defaults, chosen with the hand-crafted features.
HANDCRAFTED_THRESHOLDS: dict[str, dict[str, float]] = {
    "deepsort": {"max_cosine_distance": 0.2},
    "diversort": {"appearance_threshold": 0.10, "long_term_threshold": 0.30, "recovery_threshold": 0.30},
}


def diver_extractor(name: str) -> FeatureExtractor:
    """Appearance features: ``handcrafted``, ``learned`` (the shipped ONNX embedding) or ``FILE.onnx``."""
    if name == "handcrafted":
        return _handcrafted()
    from lookalike.vision.appearance_onnx import LEARNED_MODEL, OnnxAppearance

    if name == "learned":
        return OnnxAppearance(LEARNED_MODEL)
    if name.lower().endswith(".onnx"):
        return OnnxAppearance(Path(name))
    raise ValueError(f"features: choose handcrafted, learned or FILE.onnx, got {name!r}")


@lru_cache(maxsize=1)
def _handcrafted() -> HandcraftedFeatures:
    return fit_diver_features()


def same_diver_distances(extractor: FeatureExtractor, scenarios: tuple[DiverScenario, ...] = VALIDATION_SCENARIOS,
                         every: int = 10) -> np.ndarray:
    """Cosine distances between ground-truth crops (visibility >= 0.5) of the same diver, pooled."""
    out = []
    for sc in scenarios:
        scene = simulate_divers(sc)
        feats, labels = [], []
        for k in range(0, sc.frames, every):
            rows = scene.gt[(scene.gt[:, 0] == k + 1) & (scene.gt[:, 8] >= 0.5)]
            if len(rows):
                feats.append(extractor(scene.image(k), rows[:, 2:6]))
                labels.append(rows[:, 1])
        if not feats:
            continue
        f, lab = np.vstack(feats), np.concatenate(labels)
        for d in np.unique(lab):
            g = f[lab == d]
            iu = np.triu_indices(len(g), 1)
            out.append((1 - g @ g.T)[iu])
    return np.concatenate(out) if out else np.zeros(0)


def matched_thresholds(extractor: FeatureExtractor, tracker: str) -> dict[str, float]:
    """The tracker's cosine thresholds for ``extractor``, matched to the hand-crafted ones by quantiles of same-diver
    distances on the validation scenarios (or as stored by ``train-appearance``); empty when not applicable."""
    names = HANDCRAFTED_THRESHOLDS.get(tracker)
    if not names or isinstance(extractor, HandcraftedFeatures):
        return {}
    stored = stored_thresholds(extractor).get(tracker)
    if stored is not None and set(stored) == set(names):
        return dict(stored)
    ref = _reference_distances()
    own = _distances_of(extractor)
    return {k: _rounded(float(np.quantile(own, float(np.mean(ref <= t))))) for k, t in names.items()}


def _rounded(distance: float) -> float:
    """A cosine distance to 4 decimals, or to 4 significant digits where 4 decimals would make it 0 (no tracker
    takes a threshold of 0)."""
    return round(distance, 4) or float(f"{distance:.4g}")


def stored_thresholds(extractor: FeatureExtractor) -> dict[str, dict[str, float]]:
    """``matched_thresholds`` (tracker -> parameter -> value) stored in the JSON beside an ONNX model, or empty."""
    path = getattr(extractor, "path", None)
    meta = Path(path).with_suffix(".json") if path is not None else None
    if meta is None or not meta.is_file():
        return {}
    import json

    try:
        found = json.loads(meta.read_text()).get("matched_thresholds", {})
    except (ValueError, OSError):
        return {}
    return {t: {k: float(v) for k, v in p.items()} for t, p in found.items()} if isinstance(found, dict) else {}


@lru_cache(maxsize=1)
def _reference_distances() -> np.ndarray:
    return same_diver_distances(_handcrafted())


_DISTANCES: dict[tuple[str, int], np.ndarray] = {}


def _distances_of(extractor: FeatureExtractor) -> np.ndarray:
    key = (str(getattr(extractor, "path", type(extractor).__name__)), extractor.dim)
    if key not in _DISTANCES:
        _DISTANCES[key] = same_diver_distances(extractor)
    return _DISTANCES[key]


def prepare_features(sc: DiverScenario, extractors: dict[str, FeatureExtractor], detector: DetectorModel | None = None,
                     detector_seed: int | None = None) -> dict[str, PreparedScenario]:
    """Simulate, render, detect (``detector``: the scenario's own) and extract the detections' features with each of
    ``extractors`` (each frame rendered once): name -> scenario."""
    scene = simulate_divers(sc)
    frames: dict[str, list[Frame]] = {name: [] for name in extractors}
    for frame in scene.frames(detector, detector_seed):
        det = frame.detections
        assert det.xywh is not None  # simulated detections have boxes
        image = scene.image(frame.index) if len(det) else None
        for name, extractor in extractors.items():
            feats = extractor(image, det.xywh) if image is not None else np.zeros((0, extractor.dim))
            frames[name].append(Frame(index=frame.index, time=frame.time, detections=det.replace(feature=feats)))
    return {name: PreparedScenario(sc, scene, f, scene.gt) for name, f in frames.items()}


def run_tracker(name: str, frames: list[Frame], **params: object) -> tuple[np.ndarray, object]:
    """Run tracker ``name`` over ``frames``; MOTChallenge result rows ``(n, 10)`` and the tracker."""
    tracker = make_tracker(name, **params)
    collect = RowCollector()
    run(tracker, frames, collect)
    return collect.rows(), tracker
