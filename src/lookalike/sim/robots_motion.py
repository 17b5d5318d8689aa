"""Robot and observer motion for whole sequences at once; field coordinates (origin at the centre, x along the length,
metres), headings in radians. Every random quantity has its own stream, drawn time-major, so a shorter sequence is the
start of a longer one with the same seeds."""

from __future__ import annotations

import numpy as np

from lookalike.sim.robots_config import MotionConfig, ObserverConfig


def _lag(target: np.ndarray, alpha: float, initial: np.ndarray) -> np.ndarray:
    """First-order lag along axis 0: ``v_t = v_{t-1} + alpha (target_t - v_{t-1})``, ``v_{-1} = initial``."""
    zi = ((1.0 - alpha) * initial)[None]
    from scipy.signal import lfilter  # imported on first use: scipy.signal is slow to import

    out, _ = lfilter([alpha], [1.0, -(1.0 - alpha)], target, axis=0, zi=zi)
    return out


def _reflect(x: np.ndarray, low: float, high: float) -> np.ndarray:
    """Fold an unbounded path into ``[low, high]`` by mirror reflection at both walls."""
    span = high - low
    m = np.mod(x - low, 2.0 * span)
    return low + span - np.abs(m - span)


def simulate_motion(
    cfg: MotionConfig, field_m: tuple[float, float], n_frames: int, n_agents: int, dt_s: float,
    seeds: np.random.SeedSequence,
) -> tuple[np.ndarray, np.ndarray]:
    """Field positions ``(T, N, 2)`` (m, bouncing off the field's edges) and unwrapped headings ``(T, N)`` (rad)."""
    T, N = n_frames, n_agents
    r_switch, r_mode, r_speed, r_dir, r_turn, r_start, r_head = (np.random.default_rng(s) for s in seeds.spawn(7))
    switch = r_switch.random((T, N)) < dt_s / cfg.segment_s
    switch[0] = True
    segment = np.cumsum(switch, axis=0) - 1  # (T, N) segment index per robot
    n_seg = int(segment.max()) + 1 if T else 0
    mode = r_mode.choice(4, size=(n_seg, N), p=[cfg.p_walk, cfg.p_stand, cfg.p_turn, cfg.p_walk_turn])
    walking = (mode == 0) | (mode == 3)
    turning = (mode == 2) | (mode == 3)
    speed = cfg.max_speed_mps * np.sqrt(r_speed.random((n_seg, N)))
    direction = r_dir.uniform(-np.pi, np.pi, (n_seg, N))
    v_target = np.where(walking, speed, 0.0)[..., None] * np.stack([np.cos(direction), np.sin(direction)], -1)
    w_target = np.where(turning, r_turn.uniform(-cfg.max_turn_rate, cfg.max_turn_rate, (n_seg, N)), 0.0)
    cols = np.arange(N)[None, :]
    v_t = v_target[segment, cols]  # (T, N, 2)
    w_t = w_target[segment, cols]  # (T, N)
    # A lag of time constant tau has acceleration at most (jump of target) / tau.
    alpha_v = min(1.0, dt_s * cfg.max_accel_mps2 / (2.0 * cfg.max_speed_mps))
    alpha_w = min(1.0, dt_s * cfg.max_turn_accel / (2.0 * cfg.max_turn_rate))
    v = _lag(v_t.reshape(T, 2 * N), alpha_v, v_t[0].reshape(-1)).reshape(T, N, 2)
    w = _lag(w_t, alpha_w, w_t[0])
    half = np.array(field_m, dtype=float) / 2.0 - cfg.robot_radius_m
    start = r_start.uniform(-half, half, (N, 2))
    path = start[None] + np.cumsum(v, axis=0) * dt_s - v[:1] * dt_s
    position = np.stack([_reflect(path[..., 0], -half[0], half[0]), _reflect(path[..., 1], -half[1], half[1])], -1)
    heading = r_head.uniform(-np.pi, np.pi, N)[None] + np.cumsum(w, axis=0) * dt_s - w[:1] * dt_s
    return position, heading


def observer_pose(cfg: ObserverConfig, n_frames: int, dt_s: float, seeds: np.random.SeedSequence) -> np.ndarray:
    """Observer pose per frame ``(T, 3)``: field x, y (m) and a panning yaw (rad)."""
    t = np.arange(n_frames) * dt_s
    phase = np.random.default_rng(seeds).uniform(0, 2 * np.pi, 2)
    w = 2 * np.pi / cfg.pan_period_s
    pan = 0.5 * cfg.pan_amplitude_rad * (np.sin(w * t + phase[0]) + np.sin(w / 0.37 * t + phase[1]))
    pose = np.empty((n_frames, 3))
    pose[:, 0], pose[:, 1] = cfg.position_m
    pose[:, 2] = cfg.yaw_rad + pan
    return pose


def to_observer_frame(position_field: np.ndarray, pose: np.ndarray) -> np.ndarray:
    """Field positions ``(T, N, 2)`` into the observer frame (x forward, y left) given poses ``(T, 3)``."""
    d = position_field - pose[:, None, :2]
    c, s = np.cos(pose[:, 2])[:, None], np.sin(pose[:, 2])[:, None]
    return np.stack([c * d[..., 0] + s * d[..., 1], -s * d[..., 0] + c * d[..., 1]], -1)
