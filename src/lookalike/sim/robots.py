"""The robot world of Farazi and Behnke (IROS 2017): identical robots seen by an observer, heading reports.
Detections are in the observer frame (metres) with absolute visual headings (radians), in random order within a frame;
their ``label`` is the truth, never read by trackers."""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass

import numpy as np

from lookalike.geometry.angles import wrap_angle
from lookalike.sim.network import ReportArrays, simulate_reports
from lookalike.sim.robots_config import RobotWorldConfig
from lookalike.sim.robots_motion import (
    observer_pose,
    simulate_motion,
    to_observer_frame,
)
from lookalike.sim.robots_sensors import (
    detection_probability,
    in_view,
    occlusion_fraction,
    position_noise_std,
    visual_heading,
)
from lookalike.types import Beacons, Detections, Frame


@dataclass(frozen=True, eq=False)
class RobotArrays:
    """One simulated sequence as arrays (T frames, N robots, M detection slots).

    Attributes:
        time: ``(T,)`` frame times, seconds.
        det_valid: ``(T, M)`` whether a slot holds a detection (valid slots come first).
        det_position: ``(T, M, 2)`` observer-frame positions, metres (0 in empty slots).
        det_heading: ``(T, M)`` absolute visual headings, radians.
        det_score: ``(T, M)`` detector scores in (0, 1).
        det_label: ``(T, M)`` truth: agent id, -1 for a false positive or an empty slot.
        true_position: ``(T, N, 2)`` robots' observer-frame positions, metres.
        true_heading: ``(T, N)`` robots' absolute headings, radians.
        visible: ``(T, N)`` robot inside the field of view and range (whether detected or not).
        occlusion: ``(T, N)`` hidden fraction of each robot's width.
        field_position: ``(T, N, 2)`` robots' field positions, metres.
        observer: ``(T, 3)`` observer field pose ``(x, y, yaw)``.
        reports: the heading reports received (see :class:`ReportArrays`).
        n_false_positives: ``(T,)`` false positives made before keeping the M best.
        n_misses: ``(T,)`` visible robots not detected (before keeping the M best)."""

    time: np.ndarray
    det_valid: np.ndarray
    det_position: np.ndarray
    det_heading: np.ndarray
    det_score: np.ndarray
    det_label: np.ndarray
    true_position: np.ndarray
    true_heading: np.ndarray
    visible: np.ndarray
    occlusion: np.ndarray
    field_position: np.ndarray
    observer: np.ndarray
    reports: ReportArrays
    n_false_positives: np.ndarray
    n_misses: np.ndarray

    def __len__(self) -> int:
        return int(self.time.shape[0])


def simulate_arrays(config: RobotWorldConfig, n_frames: int, seed: int) -> RobotArrays:
    """Simulate ``n_frames`` frames of scenario ``config`` with random seed ``seed``. Each random quantity has its own
    stream, drawn frame by frame, so the first F frames of a longer run with the same seed are the run of F frames."""
    if int(n_frames) != n_frames or n_frames < 1:
        raise ValueError(f"n_frames must be a positive integer, got {n_frames!r}")
    s_motion, s_observer, s_heading, s_network, *s_draws = np.random.SeedSequence(seed).spawn(13)
    r_detect, r_noise, r_score, r_nfp, r_fp_r, r_fp_b, r_fp_head, r_fp_score, r_shuffle = (
        np.random.default_rng(s) for s in s_draws)
    T, N, M = int(n_frames), config.n_agents, config.max_detections
    dt = config.dt_s
    sensor, obs_cfg = config.sensor, config.observer
    field_pos, heading_unwrapped = simulate_motion(config.motion, config.field_m, T, N, dt, s_motion)
    pose = observer_pose(obs_cfg, T, dt, s_observer)
    rel = to_observer_frame(field_pos, pose)
    dist = np.hypot(rel[..., 0], rel[..., 1])
    bearing = np.arctan2(rel[..., 1], rel[..., 0])
    visible = in_view(rel, obs_cfg)
    occlusion = occlusion_fraction(rel, config.motion.robot_radius_m)
    p_det = np.where(visible, detection_probability(dist, occlusion, sensor, obs_cfg), 0.0)
    detected = r_detect.random((T, N)) < p_det

    # True positives: noisy positions, classifier-like headings, scores lowered by occlusion.
    tp_pos = rel + r_noise.normal(size=rel.shape) * position_noise_std(dist, sensor)
    tp_head = visual_heading(heading_unwrapped, bearing + pose[:, 2:3], sensor, s_heading)
    tp_score = r_score.beta(*sensor.tp_score_beta, (T, N)) * (1.0 - 0.5 * occlusion)

    # False positives: Poisson per frame, uniform over the visible sector (area-uniform in range), drawn one after
    # another in frame order and placed in (T, cap) slots.
    n_fp = r_nfp.poisson(sensor.fp_per_frame, T)
    cap = int(n_fp.max()) if T else 0
    fp_valid = np.arange(cap)[None, :] < n_fp[:, None]
    n_all = int(n_fp.sum())

    def per_frame(flat: np.ndarray) -> np.ndarray:
        out = np.zeros((T, cap))
        out[fp_valid] = flat
        return out

    r0, r1 = obs_cfg.min_range_m, obs_cfg.max_range_m
    fp_r = per_frame(np.sqrt(r_fp_r.uniform(r0 * r0, r1 * r1, n_all)))
    fp_b = per_frame(r_fp_b.uniform(-obs_cfg.fov_rad / 2, obs_cfg.fov_rad / 2, n_all))
    fp_pos = np.stack([fp_r * np.cos(fp_b), fp_r * np.sin(fp_b)], -1)
    fp_head = per_frame(r_fp_head.uniform(-np.pi, np.pi, n_all))
    fp_score = per_frame(r_fp_score.beta(*sensor.fp_score_beta, n_all))

    # All candidates of a frame; keep the M best scores, then shuffle slots.
    pos = np.concatenate([tp_pos, fp_pos], axis=1)
    head = np.concatenate([tp_head, fp_head], axis=1)
    score = np.clip(np.concatenate([tp_score, fp_score], axis=1), 1e-3, 1 - 1e-3)
    label = np.concatenate([np.broadcast_to(np.arange(N), (T, N)), np.full((T, cap), -1)], axis=1)
    valid = np.concatenate([detected, fp_valid], axis=1)
    rank_key = np.where(valid, score, -1.0)
    best = np.argsort(-rank_key, axis=1, kind="stable")[:, :M]
    rows = np.arange(T)[:, None]
    kept = valid[rows, best]
    shuffle_key = np.where(kept, r_shuffle.random((T, M))[:, : kept.shape[1]], 2.0)
    order = best[rows, np.argsort(shuffle_key, axis=1)]
    pad = M - order.shape[1]
    if pad > 0:  # fewer candidates than slots in every frame
        order = np.concatenate([order, np.zeros((T, pad), dtype=int)], axis=1)
    slot_valid = np.concatenate([np.sort(kept, axis=1)[:, ::-1], np.zeros((T, pad), dtype=bool)], axis=1)
    det_position = np.where(slot_valid[..., None], pos[rows, order], 0.0)
    det_heading = np.where(slot_valid, head[rows, order], 0.0)
    det_score = np.where(slot_valid, score[rows, order], 0.0)
    det_label = np.where(slot_valid, label[rows, order], -1)

    reports = simulate_reports(heading_unwrapped, dt, config.network, s_network)
    return RobotArrays(
        time=np.arange(T) * dt, det_valid=slot_valid, det_position=det_position, det_heading=det_heading,
        det_score=det_score, det_label=det_label.astype(int), true_position=rel,
        true_heading=np.asarray(wrap_angle(heading_unwrapped)), visible=visible, occlusion=occlusion,
        field_position=field_pos, observer=pose, reports=reports, n_false_positives=n_fp,
        n_misses=(visible & ~detected).sum(axis=1),
    )


class RobotSequence:
    """A simulated sequence: its scenario, seed and arrays, with frames built on demand."""

    def __init__(self, config: RobotWorldConfig, seed: int, arrays: RobotArrays) -> None:
        self.config, self.seed, self.arrays = config, seed, arrays

    def __len__(self) -> int:
        return len(self.arrays)

    def frame(self, k: int) -> Frame:
        """Frame ``k`` (0-based) with its detections (truth in ``label``) and received reports."""
        a = self.arrays
        if not 0 <= k < len(a):
            raise ValueError(f"frame index {k} out of range for a sequence of {len(a)} frames")
        n = int(a.det_valid[k].sum())
        std = self.config.sensor.heading_std_rad
        det = Detections(
            position=a.det_position[k, :n], heading=a.det_heading[k, :n], heading_std=np.full(n, std),
            score=a.det_score[k, :n], label=a.det_label[k, :n],
        )
        r = a.reports
        lo, hi = r.frame_offsets[k], r.frame_offsets[k + 1]
        beacons = Beacons(agent_id=r.agent_id[lo:hi], t_sent=r.t_sent[lo:hi], t_received=r.t_received[lo:hi],
                          heading=r.heading[lo:hi])
        return Frame(index=k, time=float(a.time[k]), detections=det, beacons=beacons)

    def frames(self) -> Iterator[Frame]:
        """All frames in order."""
        return (self.frame(k) for k in range(len(self)))

    def true_labels(self) -> list[np.ndarray]:
        """Per-frame truth labels of the detections (agent id or -1)."""
        a = self.arrays
        return [a.det_label[k, : int(a.det_valid[k].sum())] for k in range(len(a))]

    def frames_in_view(self) -> np.ndarray:
        """``(N,)`` number of frames in which each robot is inside the observer's field of view and range."""
        return np.asarray(self.arrays.visible, bool).sum(axis=0)

    def view_summary(self) -> list[str]:
        """Lines telling how many frames have each robot in view, then a warning line for each robot never in view
        (whose identity no tracker can say)."""
        counts = self.frames_in_view()
        obs = self.config.observer
        where = f"{np.degrees(obs.fov_rad):.0f}° field of view, {obs.max_range_m:g} m range"
        lines = [f"frames with each robot in view (of {len(self)}): "
                 + ", ".join(f"robot {i + 1}: {int(c)}" for i, c in enumerate(counts))]
        lines += [f"warning: robot {i + 1} is never in view ({where})" for i in np.flatnonzero(counts == 0)]
        return lines

    def true_positions_visible(self) -> np.ndarray:
        """``(T, N, 2)`` true observer-frame positions, NaN where a robot is out of view."""
        a = self.arrays
        return np.where(a.visible[..., None], a.true_position, np.nan)


def simulate_robots(config: RobotWorldConfig, n_frames: int, seed: int) -> RobotSequence:
    """Simulate a sequence and wrap it as a :class:`RobotSequence`."""
    return RobotSequence(config, seed, simulate_arrays(config, n_frames, seed))
