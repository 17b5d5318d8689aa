"""The tracking pass over a video's frames: detections from a table or a detector run on each frame, appearance
features for trackers that read them, the detector-health monitor and an optional annotated video, the frames
decoded once. Features standardised on the video itself (:class:`VideoFeatures`) are fitted from the raw features
of that same pass; the tracker then runs on those raw features, kept in a temporary file meanwhile (a second decode
only to draw)."""

from __future__ import annotations

import itertools
import time
from collections.abc import Callable, Iterable, Iterator
from contextlib import ExitStack
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from lookalike.association.solver import assign
from lookalike.geometry.boxes import iou_matrix
from lookalike.io import MotTable, frames_from_table, read_seqinfo, tracks_to_rows
from lookalike.io.video_frames import source_frames
from lookalike.loop import expect, run
from lookalike.pipeline.spill import FrameSpill
from lookalike.trackers.parts.health import HealthConfig, HealthMonitor, HealthStatus
from lookalike.types import Detections, Frame, TrackSnapshot, TrackStatus
from lookalike.vision.appearance import RAW_DIM, HandcraftedFeatures, crop_boxes, fit_stats, raw_features
from lookalike.viz.annotate import Tails
from lookalike.viz.video import VideoWriter
from lookalike.viz.video_tracking import draw_tracking_frame


@dataclass(frozen=True, eq=False)
class VideoTrackingResult:
    """What :func:`track_video` produced (frames 1-based): ``frames`` read, MOTChallenge ``rows (n, 10)``,
    ``merges`` ``(frame, source id, target id)``, one ``health`` status per frame, ``uncertain`` ``(frame, track id)``,
    ``ignored_rows`` past the video's end, and seconds in the tracker and the feature extractor."""

    frames: int
    rows: np.ndarray
    merges: list[tuple[int, int, int]]
    health: list[HealthStatus]
    uncertain: list[tuple[int, int]] = field(default_factory=list)
    ignored_rows: int = 0
    tracker_s: float = 0.0
    feature_s: float = 0.0


@dataclass(frozen=True)
class VideoFeatures:
    """Hand-crafted features standardised on the tracked video's own detections (``--features video``): up to
    ``max_crops`` boxes (every frame, or every other block of 10 frames, ...) chained frame to frame by IoU >=
    ``link_iou`` serve as identity labels for :func:`~lookalike.vision.appearance.fit_stats`; crops ``crop_px``
    px. Given to :func:`track_video` as the extractor, fitted in its pass (the raw features, about 0.45 kB per
    detection, kept in a temporary file rather than in memory)."""

    max_crops: int = 3000
    crop_px: int = 32
    link_iou: float = 0.6

    def fit(self, frames: Iterable[tuple[np.ndarray, np.ndarray | None]], boxes_total: int,
            source: Path | str, what: str = "detections") -> HandcraftedFeatures:
        """The features fitted on ``frames`` (per frame: its kept boxes ``(n, 4)`` px and their raw features, None
        where not sampled; read once, in order) of ``source``, whose detections (``what``: their file, for errors)
        hold ``boxes_total`` kept boxes. Only the sampled frames' features are kept (:meth:`blocks`)."""
        if self.max_crops < 2:
            raise ValueError(f"max_crops: must be >= 2, got {self.max_crops}")
        if boxes_total < 2:
            raise ValueError(f"{what}: fewer than 2 boxes (scoring at least --min-score) to standardise the "
                             "appearance features on")
        blocks = self.blocks(boxes_total)
        raws, labels = [], []
        prev_boxes, prev_labels, next_label = np.zeros((0, 4)), np.zeros(0, dtype=int), 0
        for k, (boxes, raw) in enumerate(frames):
            if (k // 10) % blocks or not len(boxes):
                prev_boxes, prev_labels = np.zeros((0, 4)), np.zeros(0, dtype=int)
                continue
            assert raw is not None  # (sampled)
            lab = np.arange(next_label, next_label + len(boxes))
            next_label += len(boxes)
            if len(prev_boxes):
                iou = iou_matrix(prev_boxes, boxes)
                found = assign(np.where(iou >= self.link_iou, 1.0 - iou, np.inf))
                lab[found.matches[:, 1]] = prev_labels[found.matches[:, 0]]
            raws.append(raw)
            labels.append(lab)
            prev_boxes, prev_labels = boxes, lab
        raw_all = np.vstack(raws) if raws else np.zeros((0, RAW_DIM))
        if len(raw_all) < 2:
            raise ValueError(f"{what}: fewer than 2 boxes fall on the frames of {source}")
        label = np.concatenate(labels)
        ids, counts = np.unique(label, return_counts=True)
        chained = np.isin(label, ids[counts >= 2])
        if len(ids[counts >= 2]) >= 2:
            try:
                return HandcraftedFeatures(stats=fit_stats(raw_all[chained], label[chained]), crop_px=self.crop_px)
            except ValueError:
                pass  # no dimension separates the chains: fall back to the plain statistics
        return HandcraftedFeatures(stats=fit_stats(raw_all), crop_px=self.crop_px)

    def blocks(self, boxes_total: int) -> int:
        """One block of 10 frames in this many is sampled, for ``boxes_total`` boxes."""
        return max(int(np.ceil(boxes_total / self.max_crops)), 1)


def _name(detections: MotTable | None) -> str:
    """The detections' file for errors ("detections" when read from elsewhere)."""
    return str(detections.path) if detections is not None and detections.path is not None else "detections"


def fit_video_features(source: Path | str, detections: MotTable, *, min_score: float = -np.inf,
                       max_crops: int = 3000, crop_px: int = 32, link_iou: float = 0.6) -> HandcraftedFeatures:
    """:class:`VideoFeatures` fitted on ``detections`` (1-based frames, px) scored at least ``min_score`` in a pass
    of its own over ``source``."""
    spec = VideoFeatures(max_crops, crop_px, link_iou)
    keep = detections.conf >= min_score
    frames, xywh = detections.frame[keep].astype(int), detections.xywh[keep]
    blocks = spec.blocks(len(frames))

    def read() -> Iterator[tuple[np.ndarray, np.ndarray | None]]:
        for k, image in enumerate(source_frames(source)[0] if len(frames) >= 2 else []):
            boxes = xywh[frames == k + 1]
            sampled = not (k // 10) % blocks and len(boxes)
            yield boxes, raw_features(crop_boxes(image, boxes, crop_px)) if sampled else None

    return spec.fit(read(), len(frames), source, _name(detections))


def source_frame_rate(source: Path | str) -> float | None:
    """Frame rate of an image folder from the ``seqinfo.ini`` beside it (MOTChallenge), else None."""
    p = Path(source)
    info = p.parent / "seqinfo.ini"
    if p.is_dir() and info.is_file():
        rate = read_seqinfo(info).get("frameRate")
        try:
            return float(rate) if rate is not None and float(rate) > 0 else None
        except ValueError:
            raise ValueError(f"{info}: frameRate {rate!r} is not a number") from None
    return None


def track_video(source: Path | str, detections: MotTable, tracker: Any, extractor: Any, *,
                annotate: Path | str | None = None, health: HealthConfig | None = None,
                fps: float | None = None, min_score: float = -np.inf, new_frames: int = 10,
                tail: int = 25, advance: Callable[[], None] | None = None,
                length: int | None = None, images: Iterable[np.ndarray] | None = None,
                detect: Callable[[np.ndarray], Detections] | None = None) -> VideoTrackingResult:
    """Run ``tracker`` (reset first) over ``source`` (a video file or image folder) with ``detections`` (1-based
    frames, px), features from ``extractor(image, xywh)`` (None: none, for trackers that read no appearance; a
    :class:`VideoFeatures`: fitted in this pass); with ``annotate`` also write that MP4 (unsettled identities dashed
    with ``?``, see :func:`lookalike.viz.video_tracking.draw_tracking_frame`). ``length``: the video's frames, when
    known (then, with neither features nor ``annotate``, no frame is decoded); ``images``: ``source``'s frames when
    already being read; ``detect``: a detector run on each frame in the same pass, in place of ``detections``."""
    if new_frames < 1:
        raise ValueError(f"new_frames: must be >= 1, got {new_frames}")
    frames_in: Iterable[np.ndarray | None]
    frames_in, n_declared, source_fps = source_frames(source)
    frames_in = frames_in if images is None else images
    if extractor is None and annotate is None and length is not None and detect is None:
        frames_in = itertools.repeat(None, length)  # the tracker reads only the boxes
    rate = fps or source_frame_rate(source) or source_fps
    if not rate > 0:
        raise ValueError(f"fps: must be positive, got {rate!r}")
    last_det = int(detections.frame.max()) if len(detections) else 0
    det_frames = frames_from_table(detections, max(n_declared, last_det), rate, min_score)
    tracker.reset()
    expect(tracker, max(n_declared, last_det, length or 0))
    monitor = HealthMonitor(health)
    writer = VideoWriter(annotate, fps=rate) if annotate is not None else None
    tails = Tails(length=max(tail, 1))
    first_seen: dict[int, int] = {}
    rows: list[np.ndarray] = []
    statuses: list[HealthStatus] = []
    uncertain: list[tuple[int, int]] = []
    merged_label: dict[int, tuple[int, int]] = {}  # target id -> (source id, frame of the merge)
    current: dict[str, Any] = {"merges": 0, "feature_s": 0.0}  # the frame's image, merges seen so far

    def detected() -> Iterator[tuple[np.ndarray | None, Detections]]:
        for image in frames_in:
            found = next(det_frames, None)
            det = found.detections if found is not None else Detections.empty()
            if detect is not None:
                assert image is not None  # (frames are decoded when a detector runs)
                det = detect(image)
            assert det.xywh is not None  # box detections
            yield image, det

    def frames() -> Iterator[Frame]:
        fitted = isinstance(extractor, VideoFeatures)
        counted = None if detect is not None else int((detections.conf >= min_score).sum())
        stream = _fitted_in_pass(extractor, detected(), opened.enter_context(FrameSpill()), source, counted,
                                 current, advance, annotate, _name(detections)) if fitted else detected()
        for k, (image, det) in enumerate(stream):
            t0 = time.perf_counter()
            feats = None if extractor is None else current["extractor"].normalise(det.feature) if fitted else (
                extractor(image, det.xywh) if len(det) else np.zeros((0, int(extractor.dim))))
            current["feature_s"] += time.perf_counter() - t0
            current["image"] = image
            yield Frame(index=k, time=k / rate, detections=det.replace(feature=feats))

    def sink(frame: Frame, tracks: Any) -> None:
        k, det = frame.index, frame.detections
        merges = getattr(tracker, "merges", [])
        for m in merges[current["merges"]:]:
            merged_label[int(m.target_id)] = (int(m.source_id), k)
        current["merges"] = len(merges)
        rows.append(tracks_to_rows(k, tracks))
        status = monitor.update(frame)
        statuses.append(status)
        shown = [t for t in tracks if t.xywh is not None]
        doubtful = [_uncertain(tracker, t, first_seen, k, new_frames) for t in shown]
        uncertain.extend((k + 1, t.track_id) for t, u in zip(shown, doubtful) if u)
        if writer is not None:
            assert det.xywh is not None
            writer.write(draw_tracking_frame(current["image"], k, det.xywh, shown, doubtful, merged_label, tails,
                                             new_frames, type(tracker).__name__, status))
        if advance is not None and not isinstance(extractor, VideoFeatures):
            advance()

    with ExitStack() as opened:  # the MP4 finalised and the temporary file removed, also on an error or Ctrl-C
        if writer is not None:
            opened.enter_context(writer)
        stats = run(tracker, frames(), sink)
    count, tracker_s, feature_s = stats.frames, stats.seconds, float(current["feature_s"])
    if count == 0:
        raise ValueError(f"video: {source} has no frames")
    merges = [(int(m.frame_index) + 1, int(m.source_id), int(m.target_id)) for m in getattr(tracker, "merges", [])]
    ignored = int((detections.frame > count).sum())
    table = np.vstack(rows) if rows else np.zeros((0, 10))
    return VideoTrackingResult(count, table, merges, statuses, uncertain, ignored, tracker_s, feature_s)


def _fitted_in_pass(spec: VideoFeatures, detected: Iterable[tuple[np.ndarray | None, Detections]],
                    spill: FrameSpill, source: Path | str, counted: int | None, current: dict[str, Any],
                    advance: Callable[[], None] | None, annotate: Path | str | None,
                    what: str) -> Iterator[tuple[np.ndarray | None, Detections]]:
    """The frames and detections of ``detected`` (their raw features as ``feature``) once every frame is read and
    ``spec`` fitted on them (``current["extractor"]``; ``counted``: the kept boxes of the whole detection table, None:
    those detected); the frames decoded again only to ``annotate``. Every frame's detections (boxes, scores, ...)
    and raw features wait in ``spill``, on disk: memory holds one frame, and the fit's sample."""
    for image, det in detected:
        assert image is not None and det.xywh is not None  # (frames decoded for the features)
        t0 = time.perf_counter()
        raw = raw_features(crop_boxes(image, det.xywh, spec.crop_px)) if len(det) else np.zeros((0, RAW_DIM))
        spill.append(det, raw)
        current["feature_s"] += time.perf_counter() - t0
        if advance is not None:
            advance()
    total = spill.boxes if counted is None else counted
    current["extractor"] = spec.fit(((det.xywh, det.feature) for det in spill.read()), total, source, what)
    images = source_frames(source)[0] if annotate is not None else itertools.repeat(None)
    for det, image in zip(spill.read(), images):
        yield image, det


def _uncertain(tracker: Any, t: TrackSnapshot, first_seen: dict[int, int], k: int, new_frames: int) -> bool:
    """Whether track ``t``'s identity is unsettled at frame ``k``: tentative, the tracker's ``uncertain``, or younger
    than ``new_frames``."""
    born = first_seen.setdefault(t.track_id, k)
    if t.status is TrackStatus.TENTATIVE:
        return True
    ask = getattr(tracker, "uncertain", None)
    if callable(ask):
        return bool(ask(t.track_id))
    return k - born < new_frames


__all__ = ["VideoFeatures", "VideoTrackingResult", "fit_video_features", "source_frame_rate", "track_video"]
