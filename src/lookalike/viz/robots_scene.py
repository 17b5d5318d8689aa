"""The demo's robot scene: simulate a preset, render it through the camera, run identifiers frame by frame, and write an
annotated video, a still and a bird's-eye plot of true vs estimated paths."""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from functools import partial
from pathlib import Path
from typing import Any

import numpy as np

from lookalike._optional import needs
from lookalike.eval import identification_success_rate, localisation_error
from lookalike.geometry.camera import Camera, Extrinsics, Intrinsics, Pose2D
from lookalike.loop import warm_up
from lookalike.sim import preset, preset_label, simulate_robots
from lookalike.sim.render_robots import ROBOT_HEIGHT_M, ROBOT_WIDTH_M
from lookalike.trackers import make_tracker, tracker_parameters
from lookalike.trackers.parts.identity import agent_positions, labels_from_tracks
from lookalike.viz.annotate import LabelSpace, Tails, draw_box, draw_box_label, draw_tail, with_header
from lookalike.viz.colors import identity_colour
from lookalike.viz.plots import birdseye_plot
from lookalike.viz.robot_pixels import render_robot_frames
from lookalike.viz.video import VideoWriter, write_png

WRONG = (0, 0, 230)  # BGR red outline of a wrongly identified detection
LEGEND = [("robot N (a colour per identity)", identity_colour(0), False),
          ("false positive (no robot)", identity_colour(-1), True), ("red frame: wrong label", WRONG, False)]
HOLD_FRAMES = 10  # the warm-up ends when the labels are right this many frames running (1/3 s at 30 Hz)


@dataclass
class RobotSceneResult:
    """Scores per tracker (rows, every frame), the files written, and where the video starts."""

    rows: list[dict[str, Any]]
    files: dict[str, Path] = field(default_factory=dict)
    video_tracker: str = ""
    start: int = 0  # the video's first frame (0-based): the end of the identifier's warm-up
    start_s: float = 0.0  # its time (s)


def _make(name: str, n_agents: int, n_slots: int) -> Any:
    known = {p.name for p in tracker_parameters(name)}
    params = {k: v for k, v in (("n_agents", n_agents), ("n_slots", n_slots)) if k in known}
    return make_tracker(name, **params)


def _to_fixed(ego: np.ndarray, pose: np.ndarray) -> np.ndarray:
    c, s = np.cos(pose[2]), np.sin(pose[2])
    return ego @ np.array([[c, -s], [s, c]]).T + pose[:2]


def run_robot_scene(out_dir: Path, *, preset_name: str = "m5n3", frames: int = 300, seed: int = 0,
                    trackers: list[str], video_tracker: str, render_width: int = 320, scale: int = 2,
                    advance: Callable[[], None] | None = None, rerun: Any = None) -> RobotSceneResult:
    """Simulate ``frames`` frames of ``preset_name``, run ``trackers`` and write ``robots.mp4`` and ``robots.gif``
    (from the end of ``video_tracker``'s warm-up, :func:`warm_up_end`), ``robots-still.png`` (their first frame) and
    ``robots-birdseye.png`` in ``out_dir`` (rendered ``render_width`` pixels wide, annotated at ``scale`` times, below a
    caption and legend band; ``advance`` called every frame; ``rerun`` also receives every frame)."""
    with needs("cv2"):
        import cv2

    if video_tracker not in trackers:
        raise ValueError(f"video_tracker: {video_tracker!r} is not among trackers {trackers}")
    if render_width < 64 or scale < 1:
        raise ValueError(f"render_width/scale: need >= 64 and >= 1, got {render_width}, {scale}")
    cfg = preset(preset_name)
    seq = simulate_robots(cfg, frames, seed)
    a = seq.arrays
    n = cfg.n_agents
    # A level-ish wide camera like the simulated observer's (80° field of view), so the robots fill the view.
    camera = Camera(Intrinsics.from_fov(render_width, render_width * 3 // 4, cfg.observer.fov_rad),
                    Extrinsics(0.9, np.radians(9.0)))
    for name in trackers:  # frames/s without the first frames' one-off costs (imports, compiles)
        warm_up(partial(_make, name, n, cfg.max_detections), seq.frames())
    instances = {name: _make(name, n, cfg.max_detections) for name in trackers}
    elapsed = dict.fromkeys(trackers, 0.0)
    predicted: dict[str, list[np.ndarray]] = {name: [] for name in trackers}
    estimated = {name: np.full((frames, n, 2), np.nan) for name in trackers}
    for k, frame in enumerate(seq.frames()):  # every identifier over every frame first (no pixels needed)
        for name, tracker in instances.items():
            t0 = time.perf_counter()
            tracks = tracker.update(frame)
            elapsed[name] += time.perf_counter() - t0
            predicted[name].append(labels_from_tracks(len(frame.detections), tracks))
            estimated[name][k] = agent_positions(tracks, n)
    truth_labels = seq.true_labels()
    # The video starts where the warm-up ends, by half the scene at the latest (else at the first frame by then with
    # every label right, else at the first frame).
    end = warm_up_end(predicted[video_tracker], truth_labels, latest=max(frames // 2, 1))
    settled = end is not None
    if end is None:
        end = warm_up_end(predicted[video_tracker], truth_labels, hold=1, latest=max(frames // 2, 1))
    start = end or 0
    tails = Tails(length=30, max_jump=0.5)  # 1 s at 30 Hz; an identity switch (a jump > 0.5 m) breaks it
    out_dir.mkdir(parents=True, exist_ok=True)
    files = {"video": out_dir / "robots.mp4", "gif": out_dir / "robots.gif", "still": out_dir / "robots-still.png"}
    why = "warm-up, not shown (identities learnt from heading reports)" if settled else \
        "not shown, up to the first frame with every label right"
    warm = (f"frames 1-{start} ({a.time[start]:.1f} s): {why}" if start
            else "every frame shown" + ("" if settled else ": labels not settled by half-way"))
    correct = total = 0
    with VideoWriter(files["video"], fps=cfg.frame_rate_hz, gif=files["gif"], gif_every=4, gif_frames=120,
                     atomic=True) as video:  # interrupted: an earlier robots.mp4 and .gif stay
        for k, rendered in enumerate(render_robot_frames(seq, camera, seed)):
            det = seq.frame(k).detections
            pose = a.observer[k]
            observer = Pose2D(float(pose[0]), float(pose[1]), float(pose[2]))
            img = cv2.resize(rendered.image, (rendered.image.shape[1] * scale, rendered.image.shape[0] * scale),
                             interpolation=cv2.INTER_LINEAR)
            labels, truth = predicted[video_tracker][k], truth_labels[k]
            if rerun is not None:
                _log_robots(rerun, k, float(a.time[k]), img, camera, scale, det, labels,
                            _to_fixed(estimated[video_tracker][k], pose), a.field_position[k])
            for j in range(n):
                p = estimated[video_tracker][k, j]
                if np.isfinite(p).all():
                    tails.add(k, j, _to_fixed(p[None], pose)[0])
            tails.expire(k, 60)
            if k >= start:
                correct += int((labels == truth).sum())
                total += len(labels)
                _draw_tails(img, tails, observer, camera, scale)
                _draw_detections(img, camera, scale, det, labels, truth)
                rate = f"{100.0 * correct / total:.1f}%" if total else "-"
                img = with_header(img, [
                    f"{preset_label(preset_name)} identical robots, identifier: {video_tracker}",
                    f"frame {k + 1}/{frames}  t = {a.time[k]:.1f} s  labels right since frame {start + 1}: {rate}",
                    warm], LEGEND)
                video.write(img)
                if k == start:  # the poster: the clip's first frame
                    write_png(files["still"], img)
            if advance is not None:
                advance()
    truth_pos = seq.true_positions_visible()
    rows = []
    for name in trackers:
        rows.append({
            "Setup": preset_label(preset_name), "Tracker": name,
            "Success rate (%)": round(100 * identification_success_rate(predicted[name], truth_labels), 2),
            "Localisation error (m)": round(localisation_error(estimated[name], truth_pos), 3),
            "Frames/s": round(frames / elapsed[name], 1) if elapsed[name] > 0 else float("inf"),
        })
    est_fixed = np.stack([_to_fixed(estimated[video_tracker][k], a.observer[k]) for k in range(frames)])
    files["birdseye"] = birdseye_plot(
        out_dir / "robots-birdseye.png", a.field_position, est_fixed, field_m=cfg.field_m,
        observer=cfg.observer.position_m,
        title=f"{preset_label(preset_name)}: true paths (lines) vs {video_tracker} estimates (dots), field frame",
    )
    return RobotSceneResult(rows=rows, files=files, video_tracker=video_tracker, start=start,
                            start_s=float(a.time[start]))


def warm_up_end(predicted: Sequence[np.ndarray], truth: Sequence[np.ndarray], hold: int = HOLD_FRAMES,
                latest: int | None = None) -> int | None:
    """The first frame (0-based, before ``latest``) with a robot in view from which every detection of ``hold`` frames
    is labelled right (``predicted[k]`` against ``truth[k]``, agent index or -1); None when there is none."""
    right = [bool(np.array_equal(p, t)) for p, t in zip(predicted, truth)]
    for k in range(min(len(right), latest if latest is not None else len(right))):
        if bool((np.asarray(truth[k]) >= 0).any()) and all(right[k: k + hold]):
            return k
    return None


def _draw_tails(img: np.ndarray, tails: Tails, observer: Pose2D, camera: Camera, scale: int) -> None:
    """Each identity's recent ground path (fixed frame, m) drawn through the camera."""
    for j, pts in tails.items():
        ego = observer.fixed_to_ego(pts)
        ego[~(ego[:, 0] > 0.2)] = np.nan  # behind the camera: no streak across the picture
        uv = camera.ground_to_pixels(np.nan_to_num(ego, nan=1e6)) * scale
        uv[~np.isfinite(ego).all(axis=1)] = np.nan
        draw_tail(img, uv, identity_colour(j), thickness=3)


def robot_label(label: int) -> str:
    """The label shown for agent index ``label`` (0-based in files and APIs): ``"robot 1"`` for agent 0,
    ``"false positive"`` for -1. Robots are numbered from 1 wherever they are shown."""
    return "false positive" if label < 0 else f"robot {int(label) + 1}"


def _draw_detections(img: np.ndarray, camera: Camera, scale: int, det: Any, labels: np.ndarray,
                     truth: np.ndarray) -> None:
    """Each detection's box in its identity's colour (false positives dashed grey), a red frame
    around wrong labels, and labels that avoid each other (nearest robots first)."""
    if not len(det) or det.position is None:
        return
    boxes = camera.ground_to_box(det.position, ROBOT_HEIGHT_M, ROBOT_WIDTH_M) * scale
    space = LabelSpace()
    order = np.argsort(-boxes[:, 3])  # the largest (nearest) boxes place their labels first
    for i in order:  # every box first, so that no box is drawn over a label
        b, lab = boxes[i], int(labels[i])
        draw_box(img, b, identity_colour(lab), dashed=lab < 0)
        if lab != int(truth[i]):
            draw_box(img, b + np.array([-3, -3, 6, 6]), WRONG, thickness=1)
    for i in order:
        b, lab = boxes[i], int(labels[i])
        text = robot_label(lab) + (" (wrong)" if lab != int(truth[i]) else "")
        draw_box_label(img, text, b, identity_colour(lab), space)


def _log_robots(rerun: Any, k: int, time_s: float, img: np.ndarray, camera: Camera, scale: int, det: Any,
                labels: np.ndarray, estimated: np.ndarray, truth: np.ndarray) -> None:
    rerun.set_time(k, time_s)
    rerun.image("robots/camera", img)
    boxes = camera.ground_to_box(det.position, ROBOT_HEIGHT_M, ROBOT_WIDTH_M) * scale if len(det) else np.zeros((0, 4))
    rerun.boxes("robots/camera/detections", boxes, labels,
                [robot_label(int(j)) for j in labels])
    rerun.points("robots/world/estimated", estimated, np.arange(len(estimated)))
    rerun.points("robots/world/true", truth, np.arange(len(truth)), radius=0.04)
