"""The demo's diver scenes: render, run and score every box tracker, optionally writing videos (tracks on a diver
solid, false tracks dashed red, missed divers dashed white), a still and MOTChallenge files."""

from __future__ import annotations

import time
from collections.abc import Callable
from functools import partial
from pathlib import Path
from typing import Any

import numpy as np

from lookalike._optional import needs
from lookalike.eval import evaluate_sequence
from lookalike.geometry.boxes import iou_matrix
from lookalike.io import MotTable, tracks_to_rows, write_mot
from lookalike.loop import warm_up
from lookalike.sim.divers import DiverScenario, simulate_divers
from lookalike.trackers import TrackStatus, make_tracker
from lookalike.types import Frame
from lookalike.viz.annotate import (
    LabelSpace,
    Tails,
    draw_box,
    draw_box_label,
    draw_box_tracks,
    draw_caption,
    draw_legend,
)
from lookalike.viz.colors import BGR
from lookalike.viz.video import VideoWriter

FALSE_TRACK: BGR = (40, 40, 235)  # red: a track on no diver
MISSED: BGR = (255, 255, 255)  # white: a visible diver without a track
MATCH_IOU = 0.3  # a track box on a diver (coasting boxes lag a little)


def run_diver_scenario(sc: DiverScenario, extractor: Any, trackers: list[str], *,
                       out_dir: Path | None = None, video_tracker: str | None = None,
                       advance: Callable[[], None] | None = None,
                       rerun: Any = None) -> tuple[list[dict[str, Any]], dict[str, Path]]:
    """Score ``trackers`` on ``sc`` (rows: Scenario, Tracker, IDF1, HOTA, MOTA in %, IDSW, Frames/s); with ``out_dir``
    and ``video_tracker`` also write ``divers.mp4``, ``.gif``, ``-still.png``, ``-raw.mp4`` and ``divers-<tracker>.txt``
    (``rerun`` gets the frames and boxes). Returns the rows and the files."""
    with needs("cv2"):
        import cv2

    if video_tracker is not None and (out_dir is None or video_tracker not in trackers):
        raise ValueError(f"video_tracker: {video_tracker!r} needs out_dir and must be one of {trackers}")
    scene = simulate_divers(sc)
    frames = scene.frames()
    instances = {name: make_tracker(name) for name in trackers}
    results: dict[str, list[list[float]]] = {name: [] for name in trackers}
    elapsed = dict.fromkeys(trackers, 0.0)
    files: dict[str, Path] = {}
    video = raw = None
    if video_tracker is not None and out_dir is not None:
        out_dir.mkdir(parents=True, exist_ok=True)
        files = {"video": out_dir / "divers.mp4", "gif": out_dir / "divers.gif",
                 "still": out_dir / "divers-still.png", "raw": out_dir / "divers-raw.mp4"}
        video = VideoWriter(files["video"], fps=sc.frame_rate, gif=files["gif"], gif_every=2, gif_frames=80)
        raw = VideoWriter(files["raw"], fps=sc.frame_rate)
    tails = Tails(length=25)
    warmed = False
    best_still = -1  # the still is the frame with the most tracks shown, in the second quarter onwards
    try:
        for frame in frames:
            k = frame.index
            image = scene.image(k)
            det = frame.detections
            assert det.xywh is not None  # simulated detections have boxes
            feats = extractor(image, det.xywh) if len(det) else np.zeros((0, extractor.dim))
            f = Frame(index=k, time=frame.time, detections=det.replace(feature=feats))
            if not warmed:  # frames/s without the first frame's one-off costs (imports)
                for name in trackers:
                    warm_up(partial(make_tracker, name), [f])
                warmed = True
            shown = _update_all(instances, f, results, elapsed, video_tracker)
            if rerun is not None and shown is not None:
                rerun.set_time(k, frame.time)
                rerun.image("divers/camera", image)
                rerun.boxes("divers/camera/tracks", np.array([t.xywh for t in shown]).reshape(-1, 4),
                            np.array([t.track_id for t in shown], dtype=int), [f"track {t.track_id}" for t in shown])
            if video is not None and raw is not None and shown is not None:
                raw.write(image)
                caption = [f"{sc.name}: {sc.n_divers} look-alike divers, tracker: {video_tracker}",
                           f"frame {k + 1}/{len(frames)}  t = {frame.time:.1f} s"]
                img = _annotated(image, k, scene.gt[scene.gt[:, 0] == k + 1], shown, tails, caption)
                video.write(img)
                if (k >= len(frames) // 4 and len(shown) > best_still) or not files["still"].exists():
                    best_still = len(shown) if k >= len(frames) // 4 else -1
                    cv2.imwrite(str(files["still"]), img)
            if advance is not None:
                advance()
    finally:
        if video is not None:
            video.close()
        if raw is not None:
            raw.close()
    gt = MotTable.from_rows(scene.gt)
    rows = []
    for name in trackers:
        table = np.array(results[name], dtype=float).reshape(-1, 10)
        if out_dir is not None and video_tracker is not None:
            files[f"tracks-{name}"] = write_mot(out_dir / f"divers-{name}.txt", table)
        rows.append(_score_row(sc.name, name, gt, table, len(frames), elapsed[name]))
    return rows, files


def _score_row(scenario: str, tracker: str, gt: MotTable, table: np.ndarray, n_frames: int,
               elapsed_s: float) -> dict[str, Any]:
    """One results row: IDF1, HOTA, MOTA (%), ID switches and frames per second of ``table`` against ``gt``."""
    s = evaluate_sequence(gt, MotTable.from_rows(table), num_frames=n_frames)
    return {
        "Scenario": scenario, "Tracker": tracker, "IDF1": round(100 * s["IDF1"], 1), "HOTA": round(100 * s["HOTA"], 1),
        "MOTA": round(100 * s["MOTA"], 1), "IDSW": int(s["IDSW"]),
        "Frames/s": round(n_frames / elapsed_s, 1) if elapsed_s > 0 else float("inf"),
    }


def _update_all(instances: dict[str, Any], f: Frame, results: dict[str, list[list[float]]],
                elapsed: dict[str, float], video_tracker: str | None) -> list[Any] | None:
    """Update every tracker with ``f`` (rows to ``results``, seconds to ``elapsed``); returns the video tracker's
    confirmed tracks with a box, or None."""
    shown = None
    for name, tracker in instances.items():
        t0 = time.perf_counter()
        tracks = tracker.update(f)
        elapsed[name] += time.perf_counter() - t0
        results[name].extend(tracks_to_rows(f.index, tracks).tolist())
        if name == video_tracker:
            shown = [t for t in tracks if t.xywh is not None and t.status is TrackStatus.CONFIRMED]
    return shown


def true_false_missed(track_xywh: np.ndarray, gt_rows: np.ndarray, min_iou: float = MATCH_IOU,
                      min_visibility: float = 0.3) -> tuple[np.ndarray, np.ndarray]:
    """``(on_diver (n,) bool, missed (m, 4) xywh px)``: track boxes on a diver (greedy IoU >= ``min_iou`` against
    the frame's truth rows) and the visible divers (>= ``min_visibility``) no track covers."""
    boxes = np.asarray(track_xywh, dtype=float).reshape(-1, 4)
    gt = np.asarray(gt_rows, dtype=float).reshape(-1, 9)
    gt = gt[gt[:, 8] >= min_visibility]
    on = np.zeros(len(boxes), bool)
    covered = np.zeros(len(gt), bool)
    if len(boxes) and len(gt):
        iou = iou_matrix(boxes, gt[:, 2:6])
        for flat in np.argsort(-iou, axis=None):
            i, j = np.unravel_index(flat, iou.shape)
            if iou[i, j] < min_iou:
                break
            if not on[i] and not covered[j]:
                on[i], covered[j] = True, True
    return on, gt[~covered, 2:6]


def _annotated(image: np.ndarray, k: int, gt_rows: np.ndarray, shown: list[Any], tails: Tails,
               caption: list[str]) -> np.ndarray:
    """A copy of ``image`` with the tracks (on no diver: dashed, red frame), missed divers, ``caption`` and legend."""
    img = image.copy()
    boxes = np.array([t.xywh for t in shown], dtype=float).reshape(-1, 4)
    on_diver, missed = true_false_missed(boxes, gt_rows)
    space = LabelSpace()
    for b in missed:
        draw_box(img, b, MISSED, thickness=1, dashed=True)
    for b in boxes[~on_diver]:
        draw_box(img, b + np.array([-3, -3, 6, 6]), FALSE_TRACK, thickness=2)
    draw_box_tracks(img, k, np.array([t.track_id for t in shown], dtype=int), boxes, tails, prefix="track ",
                    labels=space, dashed=~on_diver)
    for b, text, colour in [*((b, "missed", MISSED) for b in missed),
                            *((b + np.array([-3, -3, 6, 6]), "false", FALSE_TRACK) for b in boxes[~on_diver])]:
        draw_box_label(img, text, b, colour, space)
    draw_caption(img, caption)
    draw_legend(img, [("track on a diver (true)", (0, 140, 255), False),
                      ("track on no diver (false)", FALSE_TRACK, False),
                      ("diver without a track (missed)", MISSED, True)])
    return img
