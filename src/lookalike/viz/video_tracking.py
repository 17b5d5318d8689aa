"""The annotated video of a tracking pass (:func:`lookalike.pipeline.tracking.track_video`) and its side files:
unsettled identities (tentative, the tracker's ``uncertain``, or younger than ``new_frames``) dashed with ``?``,
recoveries ``id T<-S``, untaken detections thin grey dashed, an unhealthy frame a red banner."""

from __future__ import annotations

import csv
from pathlib import Path
from typing import Any

import numpy as np

from lookalike._optional import needs
from lookalike.io.outputs import atomic_path
from lookalike.trackers.parts.health import (
    HEALTH_CSV_HEADER,
    HealthStatus,
    health_row,
)
from lookalike.types import TrackSnapshot
from lookalike.viz.annotate import Tails, draw_box, draw_caption, draw_tail
from lookalike.viz.colors import FALSE_POSITIVE, identity_colour

UNHEALTHY_BGR = (40, 40, 200)


def draw_tracking_frame(image: np.ndarray, k: int, det_xywh: np.ndarray, shown: list[TrackSnapshot],
                        doubtful: list[bool], merged_label: dict[int, tuple[int, int]], tails: Tails, new_frames: int,
                        tracker_name: str, status: HealthStatus) -> np.ndarray:
    """A copy of frame ``k`` (0-based) of ``image`` with its detections ``det_xywh`` and tracks ``shown`` drawn
    (``doubtful``: unsettled, per track; ``merged_label``: target id -> (source id, frame of the merge), labelled for
    ``new_frames``; ``tails`` updated), a caption naming ``tracker_name`` and a banner when ``status`` is unhealthy."""
    img = image.copy()
    _draw(img, k, det_xywh, shown, doubtful, merged_label, new_frames, tails)
    lines = [f"{tracker_name}  frame {k + 1}",
             f"tracks: {len(shown)}  uncertain (dashed, ?): {sum(doubtful)}  detections: {len(det_xywh)}"]
    draw_caption(img, lines)
    if not status.healthy:
        draw_banner(img, "DETECTOR UNHEALTHY - identities unreliable: " + "; ".join(status.reasons
                                                                                      + status.window_reasons))
    return img


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
    """Write ``header`` and ``rows`` through :func:`~lookalike.io.outputs.atomic_path` (an interrupted write leaves
    the earlier file whole)."""
    p = Path(path)
    with atomic_path(p) as tmp, tmp.open("w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(header)
        w.writerows(rows)
    return p
