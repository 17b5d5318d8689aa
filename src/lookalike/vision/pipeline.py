"""From pixels to robot identities: HOG-cascade detector, heading classifier, ground projection through the camera,
and an identifier fed with the heading reports. Boxes ``xywh`` px; ground positions m in the observer frame; headings
absolute (observer yaw added), rad."""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Protocol

import numpy as np

from lookalike._optional import needs
from lookalike.geometry.camera import Camera
from lookalike.trackers.parts.identity import labels_from_tracks
from lookalike.trackers.registry import make_tracker, tracker_class
from lookalike.types import Beacons, Detections, Frame, TrackSnapshot

IDENTIFIERS = ("kalman_ha", "kalman_ha2", "jpda", "lstm", "set")
MODELS_DIR = Path(__file__).resolve().parent / "models_data"
SHIPPED_MODELS = {"detector": "robot_detector.npz", "heading": "robot_heading.npz"}
ROBOT_HEIGHT_M = 0.62  # height of the rendered robots (lookalike.sim.render_robots), metres
DROP_REASONS = ("outside field", "beyond range", "size")  # why RobotPipeline.perceive drops a detection


class Detector(Protocol):
    """Anything that finds boxes (``xywh`` px, ``score`` in [0, 1]) in a ``(h, w, 3)`` uint8 BGR image."""

    def __call__(self, image: np.ndarray) -> Detections: ...


class HeadingModel(Protocol):
    """Egocentric headings of boxes ``(n, 4)`` px: an object with ``heading_rad`` and ``heading_std_rad (n,)``."""

    def __call__(self, image: np.ndarray, xywh: np.ndarray) -> Any: ...


@dataclass(frozen=True)
class PipelineConfig:
    """Settings of the chain.

    Attributes:
        identifier: registered identifier name (one of :data:`IDENTIFIERS`, or any tracker reading positions and
            headings); default ``set``, which works on any team.
        n_agents: number of reporting robots N.
        max_detections: M, the most probable detections kept per frame (also the LSTM's slots).
        min_score: detector probability below which a box is dropped.
        detect_scale: resize factor before detection (> 1 finds robots smaller than the window); boxes mapped back.
        target_height_m: target height (m), to place a box whose bottom is cut by the image border.
        border_px: a box edge this close to the image border (px) counts as cut.
        identifier_params: further ``make_tracker`` parameters as ``(name, value)`` pairs.
        field_m: ``(length, width)`` of the field (m, centred on the field origin, length along x), or ``None``
            (unknown). With it, a detection whose field position lies more than ``field_margin_m`` outside is dropped
            (only in frames given the observer's field position).
        field_margin_m: tolerance of the field check (m): the ground-position error of a box near the edge.
        max_range_m: the camera's range (m): a detection whose ground position is farther is dropped; ``None``: no
            limit.
        size_tolerance: a detection whose box height differs from that of a ``target_height_m`` target standing at
            its ground position by more than this factor (either way) is dropped; ``None``: no check. Boxes touching
            the top or bottom image border are not checked."""

    identifier: str = "set"
    n_agents: int = 3
    max_detections: int = 5
    min_score: float = 0.5
    detect_scale: float = 1.0
    target_height_m: float = ROBOT_HEIGHT_M
    border_px: float = 2.0
    identifier_params: tuple[tuple[str, Any], ...] = field(default_factory=tuple)
    field_m: tuple[float, float] | None = None
    field_margin_m: float = 0.5
    max_range_m: float | None = None
    size_tolerance: float | None = None

    def __post_init__(self) -> None:
        own = "PipelineConfig"
        if int(self.n_agents) != self.n_agents or self.n_agents < 1:
            raise ValueError(f"{own}.n_agents: need a positive integer, got {self.n_agents!r}")
        if int(self.max_detections) != self.max_detections or self.max_detections < 1:
            raise ValueError(f"{own}.max_detections: need a positive integer, got {self.max_detections!r}")
        if not 0.0 <= self.min_score <= 1.0:
            raise ValueError(f"{own}.min_score: must be in [0, 1], got {self.min_score!r}")
        if not 0.25 <= self.detect_scale <= 4.0:
            raise ValueError(f"{own}.detect_scale: must be in [0.25, 4], got {self.detect_scale!r}")
        if not self.target_height_m > 0 or self.border_px < 0:
            raise ValueError(f"{own}.target_height_m/border_px: need > 0 and >= 0, got "
                             f"{self.target_height_m!r}, {self.border_px!r}")
        if self.field_m is not None and (len(self.field_m) != 2 or not min(self.field_m) > 0):
            raise ValueError(f"{own}.field_m: need (length, width) > 0 m or None, got {self.field_m!r}")
        if not self.field_margin_m >= 0:
            raise ValueError(f"{own}.field_margin_m: need >= 0 m, got {self.field_margin_m!r}")
        if self.max_range_m is not None and not self.max_range_m > 0:
            raise ValueError(f"{own}.max_range_m: need > 0 m or None, got {self.max_range_m!r}")
        if self.size_tolerance is not None and not self.size_tolerance >= 1:
            raise ValueError(f"{own}.size_tolerance: need a factor >= 1 or None, got {self.size_tolerance!r}")

    def identifier_kwargs(self) -> dict[str, Any]:
        """``make_tracker`` keyword arguments: N (and M for slot-based identifiers) plus ``identifier_params``."""
        try:
            tracker_cls: Any = tracker_class(self.identifier)
        except KeyError as exc:
            raise ValueError(f"PipelineConfig.identifier: {exc.args[0]}") from None
        known = {f.name for f in dataclasses.fields(tracker_cls.Config)}
        kwargs: dict[str, Any] = {k: v for k, v in (("n_agents", self.n_agents), ("n_slots", self.max_detections))
                                  if k in known}
        kwargs.update(dict(self.identifier_params))
        return kwargs


@dataclass(frozen=True)
class PipelineResult:
    """One frame's output: the :class:`Frame` given to the identifier (detections with ``xywh`` px, ``score``,
    ``position (n, 2)`` m, absolute ``heading`` and ``heading_std (n,)`` rad), its ``tracks``, and ``labels (n,)``:
    each detection's 0-based agent id, -1 for a false positive."""

    frame: Frame
    tracks: list[TrackSnapshot]
    labels: np.ndarray

    @property
    def detections(self) -> Detections:
        return self.frame.detections


def check_image(image: np.ndarray, size: tuple[int, int] | None = None, name: str = "image") -> np.ndarray:
    """``image`` (uint8 BGR or grey) as ``(h, w, 3)`` uint8 BGR of ``size`` (width, height) px, else ValueError."""
    if not isinstance(image, np.ndarray):
        raise ValueError(f"{name}: expected a numpy array, got {type(image).__name__}")
    if image.size == 0:
        raise ValueError(f"{name}: empty image (shape {image.shape})")
    if image.dtype != np.uint8:
        raise ValueError(f"{name}: expected dtype uint8 (BGR or grey), got {image.dtype}")
    if image.ndim == 3 and image.shape[2] == 1:
        image = image[:, :, 0]
    if image.ndim == 2:
        image = np.repeat(image[:, :, None], 3, axis=2)
    if image.ndim != 3 or image.shape[2] != 3:
        raise ValueError(f"{name}: expected shape (h, w, 3) BGR or (h, w) grey, got {image.shape}")
    if size is not None and (image.shape[1], image.shape[0]) != tuple(size):
        raise ValueError(f"{name}: is {image.shape[1]}x{image.shape[0]} px but the camera is calibrated for "
                         f"{size[0]}x{size[1]} px")
    return np.ascontiguousarray(image)


class RobotPipeline:
    """Detector → heading classifier → ground projection → identifier, one frame at a time.

    ``probability`` maps a detector's last-stage margins (one with ``boxes_and_margins``) to the score given to the
    identifier; ``None`` keeps the detector's score. Which boxes are kept does not depend on it. ``dropped`` counts
    the detections dropped since the last :meth:`reset` as implausible, by reason: ``"outside field"``, ``"beyond
    range"`` and ``"size"`` (see :class:`PipelineConfig`)."""

    def __init__(self, detector: Detector, heading: HeadingModel, camera: Camera | None = None,
                 config: PipelineConfig | None = None,
                 probability: Callable[[np.ndarray], np.ndarray] | None = None) -> None:
        self.detector = detector
        self.heading = heading
        self.probability = probability
        self.camera = camera if camera is not None else Camera.default()
        if not isinstance(self.camera, Camera):
            raise ValueError(f"camera: expected a lookalike.geometry.Camera, got {type(self.camera).__name__}")
        self.config = config if config is not None else PipelineConfig()
        try:
            self.identifier = make_tracker(self.config.identifier, **self.config.identifier_kwargs())
        except (KeyError, TypeError) as exc:
            raise ValueError(f"PipelineConfig.identifier: {exc}") from None
        self._index = 0
        self.dropped: dict[str, int] = dict.fromkeys(DROP_REASONS, 0)

    @classmethod
    def from_files(cls, detector_path: str | Path | None = None, heading_path: str | Path | None = None,
                   camera: Camera | None = None, config: PipelineConfig | None = None,
                   probability_path: str | Path | None = None) -> RobotPipeline:
        """A pipeline with models written by ``lookalike train-detector``/``train-heading`` (``None``: the shipped
        ones). Without ``probability_path`` the shipped probability map goes with the shipped detector only."""
        from lookalike.vision.detection_probability import DetectionProbability, shipped_detection_probability
        from lookalike.vision.heading import HeadingClassifier
        from lookalike.vision.hog_cascade import HogCascade

        det = HogCascade.load(detector_path if detector_path is not None else shipped_model_path("detector"))
        head = HeadingClassifier.load(heading_path if heading_path is not None else shipped_model_path("heading"))
        if probability_path is not None:
            probability: DetectionProbability | None = DetectionProbability.load(probability_path)
        else:
            probability = shipped_detection_probability() if detector_path is None else None
        return cls(det, head, camera, config, probability)

    def reset(self) -> None:
        """Start a new video: the identifier forgets its tracks and the frame counter restarts."""
        self.identifier.reset()
        self._index = 0
        self.dropped = dict.fromkeys(DROP_REASONS, 0)

    def perceive(self, image: np.ndarray, observer_yaw_rad: float = 0.0,
                 observer_xy_m: tuple[float, float] | None = None) -> Detections:
        """Detections of one frame (boxes px, scores, positions m, absolute headings and spreads rad): the
        ``max_detections`` most probable plausible ones, in decreasing score. ``observer_xy_m``: the camera's field
        position (m), which the field check needs (``None``: not checked)."""
        with needs("cv2"):
            import cv2

        cfg = self.config
        k = self.camera.intrinsics
        img = check_image(image, (k.width, k.height))
        if not np.isfinite(observer_yaw_rad):
            raise ValueError(f"observer_yaw_rad: must be finite, got {observer_yaw_rad!r}")
        if cfg.detect_scale != 1.0:
            size = (round(k.width * cfg.detect_scale), round(k.height * cfg.detect_scale))
            img_det = cv2.resize(img, size, interpolation=cv2.INTER_LINEAR)
        else:
            img_det = img
        xywh, score, rank = self._detect(img_det)
        xywh = xywh / cfg.detect_scale if cfg.detect_scale != 1.0 else xywh
        keep = (score >= cfg.min_score) & (xywh[:, 2] > 0) & (xywh[:, 3] > 0)
        xywh, score, rank = xywh[keep], score[keep], rank[keep]
        position = self.ground_positions(xywh)
        ok = np.isfinite(position).all(axis=1)
        xywh, score, rank, position = xywh[ok], score[ok], rank[ok], position[ok]
        ok = self.plausible(xywh, position, observer_yaw_rad, observer_xy_m)
        xywh, score, rank, position = xywh[ok], score[ok], rank[ok], position[ok]
        order = np.lexsort((-rank, -score))[: cfg.max_detections]
        xywh, score, rank, position = xywh[order], score[order], rank[order], position[order]
        if self.probability is not None and self._has_margins():
            score = np.asarray(self.probability(rank), float)
        if len(xywh):
            est = self.heading(img, xywh)
            heading = np.angle(np.exp(1j * (np.asarray(est.heading_rad, float) + observer_yaw_rad)))
            heading_std = np.asarray(est.heading_std_rad, float)
        else:
            heading, heading_std = np.zeros(0), np.zeros(0)
        return Detections(xywh=xywh, score=score, position=position, heading=heading, heading_std=heading_std)

    def _has_margins(self) -> bool:
        return callable(getattr(self.detector, "boxes_and_margins", None))

    def _detect(self, image: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Boxes ``(n, 4)`` px, the detector's own scores and a tie-breaking rank (the last-stage margin
        when the detector gives one, else the score)."""
        if self.probability is not None and self._has_margins():
            boxes, margins = self.detector.boxes_and_margins(image)  # type: ignore[attr-defined]
            own = self.detector.probability(margins)  # type: ignore[attr-defined]
            return np.asarray(boxes, float).reshape(-1, 4), np.asarray(own, float), np.asarray(margins, float)
        det = self.detector(image)
        assert det.xywh is not None and det.score is not None  # detectors fill boxes and scores
        return det.xywh, det.score, det.score

    def ground_positions(self, xywh: np.ndarray) -> np.ndarray:
        """Egocentric ground positions ``(n, 2)`` (m) of boxes ``(n, 4)`` (px): the bottom-centre on the ground, or
        the top-centre at the target's height when the bottom is cut; NaN where neither works."""
        b = np.asarray(xywh, float).reshape(-1, 4)
        pos = self.camera.box_to_ground(b)
        k, cfg = self.camera.intrinsics, self.config
        cut = b[:, 1] + b[:, 3] >= k.height - cfg.border_px
        if cut.any():
            top = np.column_stack([b[cut, 0] + 0.5 * b[cut, 2], b[cut, 1]])
            head = self.camera.pixels_to_ground(top, z_m=cfg.target_height_m)
            head[b[cut, 1] <= cfg.border_px] = np.nan
            pos[cut] = head
        return pos

    def plausible(self, xywh: np.ndarray, position: np.ndarray, observer_yaw_rad: float = 0.0,
                  observer_xy_m: tuple[float, float] | None = None) -> np.ndarray:
        """Which boxes ``(n, 4)`` px with egocentric ground positions ``(n, 2)`` m pass the configured field, range
        and size checks, ``(n,)`` bool; each failure is counted in ``dropped`` under its first reason."""
        cfg = self.config
        pos = np.asarray(position, float).reshape(-1, 2)
        ok = np.ones(len(pos), bool)

        def drop(reason: str, bad: np.ndarray) -> None:
            self.dropped[reason] += int((ok & bad).sum())
            ok[bad] = False

        if cfg.field_m is not None and observer_xy_m is not None:
            c, s = np.cos(observer_yaw_rad), np.sin(observer_yaw_rad)
            fx = observer_xy_m[0] + c * pos[:, 0] - s * pos[:, 1]
            fy = observer_xy_m[1] + s * pos[:, 0] + c * pos[:, 1]
            half_x, half_y = 0.5 * cfg.field_m[0] + cfg.field_margin_m, 0.5 * cfg.field_m[1] + cfg.field_margin_m
            drop("outside field", (np.abs(fx) > half_x) | (np.abs(fy) > half_y))
        if cfg.max_range_m is not None:
            drop("beyond range", np.hypot(pos[:, 0], pos[:, 1]) > cfg.max_range_m)
        if cfg.size_tolerance is not None and len(pos):
            b = np.asarray(xywh, float).reshape(-1, 4)
            h = self.camera.intrinsics.height
            inside = (b[:, 1] > cfg.border_px) & (b[:, 1] + b[:, 3] < h - cfg.border_px)
            expected = self.camera.ground_to_box(pos, cfg.target_height_m, cfg.target_height_m)[:, 3]
            with np.errstate(divide="ignore", invalid="ignore"):
                ratio = b[:, 3] / expected
            wrong = ~((ratio <= cfg.size_tolerance) & (ratio >= 1.0 / cfg.size_tolerance))
            drop("size", inside & wrong)
        return ok

    def identify(self, detections: Detections, beacons: Beacons | None = None, time_s: float | None = None,
                 index: int | None = None) -> PipelineResult:
        """Feed one frame's detections and reports to the identifier (``time_s`` default: index / 30 Hz)."""
        idx = self._index if index is None else int(index)
        t = idx / 30.0 if time_s is None else float(time_s)
        frame = Frame(index=idx, time=t, detections=detections,
                      beacons=beacons if beacons is not None else Beacons.empty())
        tracks = list(self.identifier.update(frame))
        self._index = idx + 1
        return PipelineResult(frame, tracks, labels_from_tracks(len(detections), tracks))

    def update(self, image: np.ndarray, beacons: Beacons | None = None, time_s: float | None = None,
               observer_yaw_rad: float = 0.0, observer_xy_m: tuple[float, float] | None = None) -> PipelineResult:
        """Run the whole chain on one image (uint8 BGR or grey) with the reports received since the last frame."""
        return self.identify(self.perceive(image, observer_yaw_rad, observer_xy_m), beacons, time_s)


def shipped_model_path(kind: str) -> Path:
    """The shipped model (``lookalike/vision/models_data``) for ``kind`` ``"detector"`` or ``"heading"``."""
    if kind not in SHIPPED_MODELS:
        raise ValueError(f"kind: expected one of {sorted(SHIPPED_MODELS)}, got {kind!r}")
    path = MODELS_DIR / SHIPPED_MODELS[kind]
    if not path.is_file():
        raise ValueError(f"no shipped {kind} model at {path}; train one with `lookalike train-{kind} -o FILE` "
                         f"and pass its path")
    return path


def labelled_rows(index: int, detections: Detections, labels: Sequence[int] | np.ndarray,
                  tracks: Sequence[TrackSnapshot]) -> np.ndarray:
    """MOTChallenge rows ``(k, 10)`` of 0-based frame ``index``: frame, agent id + 1, box px, confidence, x, y m, -1."""
    lab = np.asarray(labels, int).reshape(-1)
    assert detections.xywh is not None  # detections of the pixel pipeline have boxes
    prob = {t.detection_index: t.identity_prob for t in tracks if t.agent_id is not None and t.detection_index >= 0}
    rows = []
    for k in np.flatnonzero(lab >= 0):
        p = prob.get(int(k))
        pos = detections.position[k] if detections.position is not None else (np.nan, np.nan)
        rows.append([index + 1, lab[k] + 1, *detections.xywh[k], 1.0 if p is None else p, pos[0], pos[1], -1.0])
    return np.array(rows, float).reshape(-1, 10)
