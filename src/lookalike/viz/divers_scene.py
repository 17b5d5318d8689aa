"""The demo's diver scenes: render each frame once, extract appearance features, run every box
tracker online, score them (IDF1, HOTA, MOTA, ID switches, frames/s) and optionally write an
annotated video (track boxes in identity colours with tails; detections no track took are grey,
dashed and labelled "unmatched"), the raw video, a still and the MOTChallenge files.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

from lookalike.eval import evaluate_sequence
from lookalike.io import MotTable, tracks_to_rows, write_mot
from lookalike.sim.divers import DiverScenario, simulate_divers
from lookalike.trackers import TrackStatus, make_tracker
from lookalike.types import Frame
from lookalike.viz.annotate import Tails, draw_box, draw_box_tracks, draw_caption
from lookalike.viz.colors import FALSE_POSITIVE
from lookalike.viz.video import VideoWriter

Extractor = Callable[[np.ndarray, np.ndarray], np.ndarray]


def run_diver_scenario(sc: DiverScenario, extractor: Any, trackers: list[str], *,
                       out_dir: Path | None = None, video_tracker: str | None = None,
                       advance: Callable[[], None] | None = None,
                       rerun: Any = None) -> tuple[list[dict[str, Any]], dict[str, Path]]:
    """Score ``trackers`` on scenario ``sc`` (rows keyed Scenario, Tracker, IDF1, HOTA, MOTA, IDSW,
    Frames/s; metrics in %). With ``out_dir`` and ``video_tracker`` also write
    ``divers.mp4``/``divers.gif``/``divers-still.png``/``divers-raw.mp4`` and
    ``divers-<tracker>.txt``; returns the rows and the files written. ``rerun`` (a
    :class:`~lookalike.viz.rerun_log.RerunLogger`) also receives the frames and the video tracker's boxes."""
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
    best_still = -1  # the still is the frame with the most tracks shown, in the second quarter onwards
    try:
        for frame in frames:
            k = frame.index
            image = scene.image(k)
            det = frame.detections
            assert det.xywh is not None  # simulated detections have boxes
            feats = extractor(image, det.xywh) if len(det) else np.zeros((0, extractor.dim))
            f = Frame(index=k, time=frame.time, detections=det.replace(feature=feats))
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
                img = _annotated(image, k, det.xywh, shown, tails, caption)
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
    """Update every tracker with frame ``f``, appending MOTChallenge rows to ``results`` and seconds to
    ``elapsed``; returns the video tracker's confirmed tracks with a box (None without a video tracker)."""
    shown = None
    for name, tracker in instances.items():
        t0 = time.perf_counter()
        tracks = tracker.update(f)
        elapsed[name] += time.perf_counter() - t0
        results[name].extend(tracks_to_rows(f.index, tracks).tolist())
        if name == video_tracker:
            shown = [t for t in tracks if t.xywh is not None and t.status is TrackStatus.CONFIRMED]
    return shown


def _annotated(image: np.ndarray, k: int, det_xywh: np.ndarray, shown: list[Any], tails: Tails,
               caption: list[str]) -> np.ndarray:
    """A copy of ``image`` with the shown tracks (identity colours, tails), the detections no track
    took (grey, dashed, "unmatched") and ``caption``."""
    img = image.copy()
    taken = {t.detection_index for t in shown}
    for i in range(len(det_xywh)):
        if i not in taken:
            draw_box(img, det_xywh[i], FALSE_POSITIVE, "unmatched", thickness=1, dashed=True)
    draw_box_tracks(img, k, np.array([t.track_id for t in shown], dtype=int),
                    np.array([t.xywh for t in shown]).reshape(-1, 4), tails, prefix="track ")
    draw_caption(img, caption)
    return img
