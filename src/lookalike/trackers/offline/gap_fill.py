"""Offline post-processing of a finished result (never inside an online ``update``): link broken tracks,
fill short gaps, smooth boxes. Rows are MOTChallenge results ``(k, 10)`` (1-based frame, id, xywh in pixels, ...).

- :func:`link_tracks`: a track ending at frame ``a`` and one starting at ``b``, ``0 < b - a <= link_gap_s``
  seconds, are extrapolated towards each other at their mean velocities; pairs whose mean centre miss is
  within ``link_distance`` box heights and sizes within a factor ``scale`` are linked by a minimum-cost
  assignment (the later track takes the earlier id).
- :func:`fill_gaps`: gaps of at most ``fill_gap_s`` seconds inside one id are interpolated linearly.
- :func:`smooth_boxes`: each id's centres and sizes replaced by their running median."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from lookalike.association.solver import assign
from lookalike.trackers.base import check_positive, param


@dataclass(frozen=True)
class OfflineConfig:
    """Parameters of :func:`postprocess` (gaps in frames, distances in box heights)."""

    link_gap_s: float = param(0.0, "longest gap (seconds) between the end of one track and the start of another it "
                                   "continues (0: no linking)")
    link_distance: float = param(1.0, "largest mean centre miss (box heights) of a link")
    scale: float = param(1.5, "largest width/height ratio between the boxes either side of a link")
    velocity_frames: int = param(5, "boxes at a track's end/start that give its velocity")
    coast_s: float = param(0.5, "seconds a track end/start is extrapolated at its velocity (then held)")
    fill_gap_s: float = param(2.0, "longest run of missing frames (seconds) inside one id that is interpolated")

    def __post_init__(self) -> None:
        check_positive(self, "link_gap_s", "link_distance", "coast_s", "fill_gap_s", allow_zero=True)
        check_positive(self, "velocity_frames")
        if self.scale < 1:
            raise ValueError(f"OfflineConfig.scale must be >= 1, got {self.scale}")


def _check_rows(rows: np.ndarray) -> np.ndarray:
    arr = np.asarray(rows, dtype=float)
    if arr.ndim != 2 or arr.shape[1] < 6:
        raise ValueError(f"rows: expected MOTChallenge rows (k, >=6), got shape {arr.shape}")
    return arr


def _ends(frames: np.ndarray, boxes: np.ndarray, k: int) -> tuple[np.ndarray, np.ndarray]:
    """Centre ``(2,)`` px and velocity ``(2,)`` px/frame of the last ``k`` boxes of one track."""
    centre = boxes[:, :2] + boxes[:, 2:4] / 2
    f, c = frames[-k:], centre[-k:]
    velocity = (c[-1] - c[0]) / (f[-1] - f[0]) if len(f) > 1 and f[-1] > f[0] else np.zeros(2)
    return centre[-1], velocity


def _frames(seconds: float, frame_rate: float) -> int:
    if not frame_rate > 0:
        raise ValueError(f"frame_rate must be > 0 frames/s, got {frame_rate}")
    return round(seconds * frame_rate)


def link_tracks(rows: np.ndarray, frame_rate: float, config: OfflineConfig | None = None) -> np.ndarray:
    """``rows`` with ids of linked tracks merged (the earliest id of a chain is kept);
    ``frame_rate`` in frames/s converts the config's seconds to frames."""
    cfg = config or OfflineConfig()
    rows = _check_rows(rows).copy()
    link_gap, coast = _frames(cfg.link_gap_s, frame_rate), _frames(cfg.coast_s, frame_rate)
    if not len(rows) or link_gap == 0:
        return rows
    ids = np.unique(rows[:, 1].astype(int))
    info = []
    for i in ids:
        sel = rows[rows[:, 1] == i]
        sel = sel[np.argsort(sel[:, 0], kind="stable")]
        f, b = sel[:, 0], sel[:, 2:6]
        c_end, v_end = _ends(f, b, cfg.velocity_frames)
        c_start, v_start = _ends(f[::-1], b[::-1], cfg.velocity_frames)  # backward in time
        info.append((f[0], f[-1], b[0, 2:4], b[-1, 2:4], c_start, v_start, c_end, v_end))
    n = len(ids)
    first = np.array([t[0] for t in info])
    last = np.array([t[1] for t in info])
    gap = first[None, :] - last[:, None]  # [end of i, start of j]
    cost = np.full((n, n), np.inf)
    for a, b in zip(*np.nonzero((gap > 0) & (gap <= link_gap))):
        g = min(gap[a, b], coast)
        size_a, size_b = info[a][3], info[b][2]
        if np.abs(np.log(np.maximum(size_a, 1.0) / np.maximum(size_b, 1.0))).max() > np.log(cfg.scale):
            continue
        forward = np.linalg.norm(info[a][6] + info[a][7] * g - info[b][4]) / max(size_b[1], 1.0)
        backward = np.linalg.norm(info[b][4] + info[b][5] * g - info[a][6]) / max(size_a[1], 1.0)
        miss = (forward + backward) / 2
        if miss <= cfg.link_distance:
            cost[a, b] = miss
    successor = np.full(n, -1)
    for a, b in assign(cost).matches:
        successor[a] = b
    new_id = ids.copy()
    has_pred = np.zeros(n, dtype=bool)
    has_pred[successor[successor >= 0]] = True
    for head in np.flatnonzero(~has_pred):  # follow each chain from its first track
        k = successor[head]
        while k >= 0:
            new_id[k] = ids[head]
            k = successor[k]
    lookup = dict(zip(ids.tolist(), new_id.tolist()))
    rows[:, 1] = [lookup[int(i)] for i in rows[:, 1]]
    return rows


def fill_gaps(rows: np.ndarray, max_gap: int) -> np.ndarray:
    """``rows`` plus linearly interpolated boxes for runs of at most ``max_gap`` missing frames
    inside each id's span (sorted by frame, then id)."""
    rows = _check_rows(rows)
    if max_gap < 0:
        raise ValueError(f"max_gap must be >= 0, got {max_gap}")
    out = [rows]
    for i in np.unique(rows[:, 1]):
        sel = rows[rows[:, 1] == i]
        sel = sel[np.argsort(sel[:, 0], kind="stable")]
        steps = np.diff(sel[:, 0])
        for k in np.flatnonzero((steps > 1) & (steps <= max_gap + 1)):
            a, b = sel[k], sel[k + 1]
            t = (np.arange(a[0] + 1, b[0]) - a[0]) / (b[0] - a[0])
            new = np.repeat(a[None, :], len(t), axis=0)
            new[:, 0] = np.arange(a[0] + 1, b[0])
            new[:, 2:6] = a[2:6] + t[:, None] * (b[2:6] - a[2:6])
            out.append(new)
    merged = np.vstack(out)
    return merged[np.lexsort((merged[:, 1], merged[:, 0]))]


def smooth_boxes(rows: np.ndarray, window: int) -> np.ndarray:
    """``rows`` with each id's box centres and widths/heights replaced by their running median over ``window``
    consecutive rows of that id (1 or less: unchanged; the first and last rows repeated beyond the ends)."""
    rows = _check_rows(rows)
    half = int(window) // 2
    out: np.ndarray = rows.copy()
    if half < 1 or not len(rows):
        return out
    from numpy.lib.stride_tricks import sliding_window_view

    for i in np.unique(rows[:, 1]):
        sel = np.flatnonzero(rows[:, 1] == i)
        sel = sel[np.argsort(rows[sel, 0], kind="stable")]
        box = rows[sel, 2:6]
        values = np.column_stack([box[:, :2] + box[:, 2:4] / 2, box[:, 2:4]])
        pad = np.pad(values, ((half, half), (0, 0)), mode="edge")
        med = np.median(sliding_window_view(pad, 2 * half + 1, axis=0), axis=2)
        out[sel, 2:4] = med[:, :2] - med[:, 2:4] / 2
        out[sel, 4:6] = med[:, 2:4]
    return out


def postprocess(rows: np.ndarray, frame_rate: float, config: OfflineConfig | None = None) -> np.ndarray:
    """:func:`link_tracks`, then :func:`fill_gaps` (``config.fill_gap_s``) on a whole result;
    ``frame_rate`` in frames/s."""
    cfg = config or OfflineConfig()
    return fill_gaps(link_tracks(rows, frame_rate, cfg), _frames(cfg.fill_gap_s, frame_rate))
