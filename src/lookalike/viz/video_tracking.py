"""Tracking on real video: MOTChallenge detections, appearance features from the pixels, any tracker, the
detector-health monitor and an optional annotated video: unsettled identities (tentative, the tracker's ``uncertain``,
or younger than ``new_frames``) dashed with ``?``, recoveries ``id T<-S``, untaken detections thin grey dashed, an
unhealthy frame a red banner."""

from __future__ import annotations

import csv
import itertools
import time
from collections.abc import Callable, Iterable, Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from lookalike._optional import needs
from lookalike.association.solver import assign
from lookalike.geometry.boxes import iou_matrix
from lookalike.io import MotTable, frames_from_table, read_seqinfo, tracks_to_rows
from lookalike.loop import run
from lookalike.trackers.parts.health import (
    HEALTH_CSV_HEADER,
    HealthConfig,
    HealthMonitor,
    HealthStatus,
    health_row,
)
from lookalike.types import Detections, Frame, TrackSnapshot, TrackStatus
from lookalike.vision.appearance import (
    RAW_DIM,
    HandcraftedFeatures,
    crop_boxes,
    fit_stats,
    raw_features,
)
from lookalike.viz.annotate import Tails, draw_box, draw_caption, draw_tail
from lookalike.viz.colors import FALSE_POSITIVE, identity_colour
from lookalike.viz.overlay import source_frames
from lookalike.viz.video import VideoWriter

UNHEALTHY_BGR = (40, 40, 200)


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


def fit_video_features(source: Path | str, detections: MotTable, *, min_score: float = -np.inf,
                       max_crops: int = 3000, crop_px: int = 32, link_iou: float = 0.6) -> HandcraftedFeatures:
    """Hand-crafted features standardised on this video's detections: up to ``max_crops`` boxes chained frame to
    frame by IoU >= ``link_iou`` serve as identity labels for :func:`~lookalike.vision.appearance.fit_stats`."""
    if max_crops < 2:
        raise ValueError(f"max_crops: must be >= 2, got {max_crops}")
    keep = detections.conf >= min_score
    frames = detections.frame[keep].astype(int)
    if len(frames) < 2:
        raise ValueError("detections: fewer than 2 boxes to standardise the appearance features on")
    xywh = detections.xywh[keep]
    blocks = max(int(np.ceil(len(frames) / max_crops)), 1)
    images, _, _ = source_frames(source)
    raws, labels = [], []
    prev_boxes, prev_labels, next_label = np.zeros((0, 4)), np.zeros(0, dtype=int), 0
    for k, image in enumerate(images):
        boxes = xywh[frames == k + 1]
        if (k // 10) % blocks or not len(boxes):
            prev_boxes, prev_labels = np.zeros((0, 4)), np.zeros(0, dtype=int)
            continue
        lab = np.arange(next_label, next_label + len(boxes))
        next_label += len(boxes)
        if len(prev_boxes):
            iou = iou_matrix(prev_boxes, boxes)
            found = assign(np.where(iou >= link_iou, 1.0 - iou, np.inf))
            lab[found.matches[:, 1]] = prev_labels[found.matches[:, 0]]
        raws.append(raw_features(crop_boxes(image, boxes, crop_px)))
        labels.append(lab)
        prev_boxes, prev_labels = boxes, lab
    raw = np.vstack(raws) if raws else np.zeros((0, RAW_DIM))
    if len(raw) < 2:
        raise ValueError(f"detections: fewer than 2 boxes fall on the frames of {source}")
    label = np.concatenate(labels)
    ids, counts = np.unique(label, return_counts=True)
    chained = np.isin(label, ids[counts >= 2])
    if len(ids[counts >= 2]) >= 2:
        try:
            return HandcraftedFeatures(stats=fit_stats(raw[chained], label[chained]), crop_px=crop_px)
        except ValueError:
            pass  # no dimension separates the chains: fall back to the plain statistics
    return HandcraftedFeatures(stats=fit_stats(raw), crop_px=crop_px)


def track_video(source: Path | str, detections: MotTable, tracker: Any, extractor: Any, *,
                annotate: Path | str | None = None, health: HealthConfig | None = None,
                fps: float | None = None, min_score: float = -np.inf, new_frames: int = 10,
                tail: int = 25, advance: Callable[[], None] | None = None,
                length: int | None = None, images: Iterable[np.ndarray] | None = None,
                detect: Callable[[np.ndarray], Detections] | None = None) -> VideoTrackingResult:
    """Run ``tracker`` (reset first) over ``source`` (a video file or image folder) with ``detections`` (1-based
    frames, px), features from ``extractor(image, xywh)`` (None: none, for trackers that read no appearance); with
    ``annotate`` also write that MP4. ``length``: the video's frames, when known (then, with neither features nor
    ``annotate``, no frame is decoded); ``images``: ``source``'s frames when already being read; ``detect``: a
    detector run on each frame in the same pass, in place of ``detections``."""
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
    monitor = HealthMonitor(health)
    writer = VideoWriter(annotate, fps=rate) if annotate is not None else None
    tails = Tails(length=max(tail, 1))
    first_seen: dict[int, int] = {}
    rows: list[np.ndarray] = []
    statuses: list[HealthStatus] = []
    uncertain: list[tuple[int, int]] = []
    merged_label: dict[int, tuple[int, int]] = {}  # target id -> (source id, frame of the merge)
    current: dict[str, Any] = {"merges": 0, "feature_s": 0.0}  # the frame's image, merges seen so far

    def frames() -> Iterator[Frame]:
        for k, image in enumerate(frames_in):
            found = next(det_frames, None)
            det = found.detections if found is not None else Detections.empty()
            if detect is not None:
                assert image is not None  # (frames are decoded when a detector runs)
                det = detect(image)
            t0 = time.perf_counter()
            assert det.xywh is not None  # box detections
            feats = None if extractor is None else extractor(image, det.xywh) if len(det) else np.zeros(
                (0, int(extractor.dim)))
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
            img = current["image"].copy()
            _draw(img, k, det.xywh, shown, doubtful, merged_label, new_frames, tails)
            lines = [f"{type(tracker).__name__}  frame {k + 1}",
                     f"tracks: {len(shown)}  uncertain (dashed, ?): {sum(doubtful)}  detections: {len(det)}"]
            draw_caption(img, lines)
            if not status.healthy:
                draw_banner(img, "DETECTOR UNHEALTHY - identities unreliable: "
                            + "; ".join(status.reasons + status.window_reasons))
            writer.write(img)
        if advance is not None:
            advance()

    try:
        stats = run(tracker, frames(), sink)
    finally:
        if writer is not None:
            writer.close()
    count, tracker_s, feature_s = stats.frames, stats.seconds, float(current["feature_s"])
    if count == 0:
        raise ValueError(f"video: {source} has no frames")
    merges = [(int(m.frame_index) + 1, int(m.source_id), int(m.target_id)) for m in getattr(tracker, "merges", [])]
    ignored = int((detections.frame > count).sum())
    table = np.vstack(rows) if rows else np.zeros((0, 10))
    return VideoTrackingResult(count, table, merges, statuses, uncertain, ignored, tracker_s, feature_s)


def _uncertain(tracker: Any, t: TrackSnapshot, first_seen: dict[int, int], k: int, new_frames: int) -> bool:
    """Whether track ``t``'s identity is unsettled at frame ``k`` (see the module docstring)."""
    born = first_seen.setdefault(t.track_id, k)
    if t.status is TrackStatus.TENTATIVE:
        return True
    ask = getattr(tracker, "uncertain", None)
    if callable(ask):
        return bool(ask(t.track_id))
    return k - born < new_frames


def _draw(img: np.ndarray, k: int, det_xywh: np.ndarray, shown: list[TrackSnapshot], doubtful: list[bool],
          merged_label: dict[int, tuple[int, int]], new_frames: int, tails: Tails) -> None:
    taken = {t.detection_index for t in shown if t.detection_index is not None}
    for i, box in enumerate(np.asarray(det_xywh).reshape(-1, 4)):
        if i not in taken:
            draw_box(img, box, FALSE_POSITIVE, None, thickness=1, dashed=True)
    for t in shown:
        assert t.xywh is not None
        b = t.xywh
        tails.add(k, t.track_id, np.array([b[0] + b[2] / 2, b[1] + b[3]]))
    tails.expire(k, 5)
    for i, pts in tails.items():
        draw_tail(img, pts, identity_colour(i))
    for t, u in zip(shown, doubtful):
        assert t.xywh is not None
        label = f"id {t.track_id}"
        src = merged_label.get(t.track_id)
        if src is not None and k - src[1] < new_frames:
            label += f"<-{src[0]}"
        draw_box(img, t.xywh, identity_colour(t.track_id), label + ("?" if u else ""), dashed=u)


def draw_banner(image: np.ndarray, text: str, colour: tuple[int, int, int] = UNHEALTHY_BGR) -> None:
    """A band of ``colour`` across the bottom of ``image`` (in place) with white ``text``, cut to fit."""
    with needs("cv2"):
        import cv2

    scale, h = 0.45, 22
    width = image.shape[1] - 12
    while text and cv2.getTextSize(text, cv2.FONT_HERSHEY_SIMPLEX, scale, 1)[0][0] > width:
        text = text[: max(len(text) - 4, 0)] + "..." if len(text) > 4 else ""
    band = image[max(image.shape[0] - h, 0):]
    band[:] = (band.astype(np.uint16) * 2 // 5 + np.array(colour, dtype=np.uint16) * 3 // 5).astype(np.uint8)
    cv2.putText(image, text, (6, image.shape[0] - 7), cv2.FONT_HERSHEY_SIMPLEX, scale, (255, 255, 255), 1,
                cv2.LINE_AA)


def side_file(output: Path | str, kind: str) -> Path:
    """The side file ``<output stem>.<kind>.csv`` next to a result file."""
    p = Path(output)
    return p.with_name(f"{p.stem}.{kind}.csv")


def write_merges_csv(path: Path | str, merges: list[tuple[int, int, int]]) -> Path:
    """``frame,source_id,target_id`` (frame 1-based; from that frame on the source is reported as the target)."""
    return _write_csv(path, ["frame", "source_id", "target_id"], merges)


def write_health_csv(path: Path | str, statuses: list[HealthStatus]) -> Path:
    """One row per frame, columns :data:`~lookalike.trackers.parts.health.HEALTH_CSV_HEADER`."""
    return _write_csv(path, HEALTH_CSV_HEADER, [health_row(s) for s in statuses])


def _write_csv(path: Path | str, header: Any, rows: Any) -> Path:
    p = Path(path)
    p.parent.mkdir(parents=True, exist_ok=True)
    with p.open("w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(header)
        w.writerows(rows)
    return p
