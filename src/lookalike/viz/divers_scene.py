"""The demo's diver scenes: render, run and score every box tracker, optionally writing videos (tracks on a diver
solid, false tracks dashed red, missed divers dashed white), a still and MOTChallenge files."""

from __future__ import annotations

import time
from collections.abc import Callable
from contextlib import nullcontext
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
    with_header,
)
from lookalike.viz.colors import BGR
from lookalike.viz.video import VideoWriter, write_png

FALSE_TRACK: BGR = (40, 40, 235)  # red: a track on no diver
MISSED: BGR = (255, 255, 255)  # white: a visible diver without a track
MATCH_IOU = 0.3  # a track box on a diver (coasting boxes lag a little)
MIN_VISIBILITY = 0.3  # a diver counts as in view (and can be missed) from this visible fraction
LEGEND: list[tuple[str, BGR, bool]] = [
    ("track on a diver", (0, 140, 255), False), ("red frame: track on no diver", FALSE_TRACK, False),
    ("missed diver (no track)", MISSED, True)]


def run_diver_scenario(sc: DiverScenario, extractor: Any, trackers: list[str], *,
                       out_dir: Path | None = None, video_tracker: str | None = None,
                       advance: Callable[[], None] | None = None,
                       rerun: Any = None) -> tuple[list[dict[str, Any]], dict[str, Path], float | None]:
    """Score ``trackers`` on ``sc`` (rows: Scenario, Tracker, IDF1, HOTA, MOTA in %, IDSW, Frames/s, every frame);
    with ``out_dir`` and ``video_tracker`` also write ``divers.mp4`` (from the end of the warm-up, see :class:`_Clip`),
    ``.gif``, ``-still.png`` (its first frame), ``-raw.mp4`` (every frame) and ``divers-<tracker>.txt`` (``rerun``
    gets the frames and boxes). Returns the rows, the files and the time (s) where the video starts (None without)."""
    with needs("cv2"):  # the renderer and the feature extractor need it: fail before any work
        import cv2  # noqa: F401

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
        video = VideoWriter(files["video"], fps=sc.frame_rate, gif=files["gif"], gif_every=2, gif_frames=80,
                            atomic=True)
        raw = VideoWriter(files["raw"], fps=sc.frame_rate, atomic=True)
    clip = _Clip(sc, video_tracker, len(frames), video, files.get("still"))
    warmed = False
    with video or nullcontext(), raw or nullcontext():  # (atomic: interrupted, no unfinished video replaces one)
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
                clip.add(k, frame.time, image, scene.gt[scene.gt[:, 0] == k + 1], shown, scene.image)
            if advance is not None:
                advance()

    gt = MotTable.from_rows(scene.gt)
    rows = []
    for name in trackers:
        table = np.array(results[name], dtype=float).reshape(-1, 10)
        if out_dir is not None and video_tracker is not None:
            files[f"tracks-{name}"] = write_mot(out_dir / f"divers-{name}.txt", table)
        rows.append(_score_row(sc.name, name, gt, table, len(frames), elapsed[name]))
    return rows, files, (clip.start_s if clip.start is not None else None)


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
                      min_visibility: float = MIN_VISIBILITY) -> tuple[np.ndarray, np.ndarray]:
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


class _Clip:
    """The annotated diver video: it starts at the first frame where every visible diver has a track and no track is
    false (the trackers' warm-up ends), or, when that has not happened by half the scene, at the first frame with the
    fewest misses so far; that first frame is also the still. The caption counts the divers tracked since then."""

    def __init__(self, sc: DiverScenario, tracker: str | None, n_frames: int, video: VideoWriter | None,
                 still: Path | None) -> None:
        self.sc, self.tracker, self.n_frames, self.video, self.still = sc, tracker, n_frames, video, still
        self.start: int | None = None
        self.start_s = 0.0
        self.clean = False  # whether the start frame has every diver tracked
        self.tails = Tails(length=25)
        self.seen: list[tuple[float, np.ndarray, list[Any], int]] = []  # per frame: time, truth, tracks, errors
        self.visible = self.tracked = 0

    def add(self, k: int, time_s: float, image: np.ndarray, gt_rows: np.ndarray, shown: list[Any],
            render: Callable[[int], np.ndarray]) -> None:
        """Frame ``k`` (0-based, in order) at ``time_s`` (s): its image, truth rows and shown tracks; ``render(j)``
        redraws an earlier frame ``j`` when the clip starts before ``k``."""
        boxes = np.array([t.xywh for t in shown], dtype=float).reshape(-1, 4)
        on, missed = true_false_missed(boxes, gt_rows)
        errors = len(missed) + int((~on).sum()) if (gt_rows[:, 8] >= MIN_VISIBILITY).any() else -1
        self.seen.append((time_s, gt_rows, shown, errors))
        if self.start is None:
            if errors == 0:
                self.start, self.clean = k, True
            elif k + 1 >= max(self.n_frames // 2, 1):
                scores = [e if e >= 0 else 10**6 for *_, e in self.seen]
                self.start = int(np.argmin(scores))
            if self.start is None:
                return
            self.start_s = self.seen[self.start][0]
            for j in range(self.start, k):
                self._emit(j, render(j))
        self._emit(k, image)

    def _emit(self, j: int, image: np.ndarray) -> None:
        time_s, gt_rows, shown, _ = self.seen[j]
        boxes = np.array([t.xywh for t in shown], dtype=float).reshape(-1, 4)
        in_view = int((gt_rows[:, 8] >= MIN_VISIBILITY).sum())
        self.visible += in_view
        self.tracked += in_view - len(true_false_missed(boxes, gt_rows)[1])
        rate = f"{100.0 * self.tracked / self.visible:.1f}%" if self.visible else "-"
        assert self.start is not None
        why = "until every diver had a track" if self.clean else "up to the fewest misses in the first half"
        warm = f"frames 1-{self.start} ({self.start_s:.1f} s): warm-up, not shown ({why})" if self.start else ""
        caption = [f"{self.sc.name}: {self.sc.n_divers} look-alike divers, tracker: {self.tracker}",
                   f"frame {j + 1}/{self.n_frames}  t = {time_s:.1f} s  divers tracked since frame {self.start + 1}: "
                   f"{rate}", warm or "every frame shown"]
        img = _annotated(image, j, gt_rows, shown, self.tails, caption)
        if self.video is not None:
            self.video.write(img)
        if j == self.start and self.still is not None:
            write_png(self.still, img)


def _annotated(image: np.ndarray, k: int, gt_rows: np.ndarray, shown: list[Any], tails: Tails,
               caption: list[str]) -> np.ndarray:
    """``image`` with the tracks (on no diver: dashed, red frame) and missed divers drawn, below a band with
    ``caption`` and the legend."""
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
    return with_header(img, caption, LEGEND)
