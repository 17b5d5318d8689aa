"""Tracklets for the offline closed set: an online result cut into reliable pieces (:func:`split_tracklets`) and the
links between the end of one piece and the start of a later one scored under two motion hypotheses (:func:`link_costs`);
:mod:`lookalike.trackers.offline.closed_set` says how both are used. Positions in pixels, sizes √(w·h) in pixels, times
in frames."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from lookalike.geometry.boxes import iou_matrix
from lookalike.trackers.offline.closed_set_config import ClosedSetConfig

__all__ = ["Tracklet", "checked_rows", "link_costs", "motion_scale", "row_centres", "row_sizes", "row_steps",
           "split_tracklets"]


@dataclass(frozen=True, eq=False)
class Tracklet:
    """A piece of one track: its rows ``(k, 10)`` sorted by frame (consecutive frames)."""

    rows: np.ndarray
    source_id: int = -1  # the id it had in the input
    contact: bool = False  # every row touches another track's box (identity there is unsure)

    @property
    def first(self) -> int:
        return int(self.rows[0, 0])

    @property
    def last(self) -> int:
        return int(self.rows[-1, 0])

    def __len__(self) -> int:
        return len(self.rows)


def row_centres(rows: np.ndarray) -> np.ndarray:
    return rows[:, 2:4] + rows[:, 4:6] / 2


def row_sizes(rows: np.ndarray) -> np.ndarray:
    out: np.ndarray = np.sqrt(np.maximum(rows[:, 4] * rows[:, 5], 1.0))
    return out


def checked_rows(rows: np.ndarray) -> np.ndarray:
    """``rows`` as float MOTChallenge rows ``(k, 10)`` (missing columns -1); ``ValueError`` for another shape or a row
    whose frame is not a whole number >= 1 or whose id or box (pixels) is not finite."""
    arr = np.asarray(rows, dtype=float)
    if arr.ndim != 2 or (arr.size and arr.shape[1] < 6):
        raise ValueError(f"rows: expected MOTChallenge rows (k, >=6), got shape {arr.shape}")
    bad = np.flatnonzero(~np.isfinite(arr[:, :6]).all(axis=1) | (arr[:, 0] < 1) | (arr[:, 0] % 1 != 0)) \
        if arr.size else np.zeros(0, int)
    if len(bad):
        raise ValueError(f"rows[{bad[0]}]: needs a whole frame >= 1 and a finite id and box, got "
                         f"{arr[bad[0], :6].tolist()}")
    if arr.size and arr.shape[1] < 10:
        arr = np.hstack([arr, np.full((len(arr), 10 - arr.shape[1]), -1.0)])
    return arr.reshape(-1, 10) if not arr.size else arr


def row_steps(rows: np.ndarray) -> np.ndarray:
    """Per-frame centre steps (pixels) between consecutive-frame rows of the same id."""
    order = np.lexsort((rows[:, 0], rows[:, 1]))
    r = rows[order]
    same = (np.diff(r[:, 1]) == 0) & (np.diff(r[:, 0]) == 1)
    steps: np.ndarray = np.linalg.norm(np.diff(row_centres(r), axis=0), axis=1)[same]
    return steps


def _contact_frames(rows: np.ndarray, min_iou: float) -> np.ndarray:
    """Row mask: the box overlaps another id's box in the same frame by IoU ≥ ``min_iou``."""
    hit = np.zeros(len(rows), dtype=bool)
    order = np.argsort(rows[:, 0], kind="stable")
    frames = rows[order, 0]
    bounds = np.flatnonzero(np.diff(frames)) + 1
    for idx in np.split(order, bounds):
        if len(idx) < 2:
            continue
        iou = iou_matrix(rows[idx, 2:6], rows[idx, 2:6])
        np.fill_diagonal(iou, 0.0)
        hit[idx] = (iou >= min_iou).any(axis=1)
    return hit


def _fill_short(mask: np.ndarray, k: int) -> np.ndarray:
    """``mask`` with runs of fewer than ``k`` False values between two True values set True (a contact
    that flickers for a few frames is one contact)."""
    out: np.ndarray = mask.copy()
    on = np.flatnonzero(mask)
    for a, b in zip(on[:-1], on[1:]):
        if 1 < b - a <= k:
            out[a:b] = True
    return out


def split_tracklets(rows: np.ndarray, config: ClosedSetConfig | None = None) -> list[Tracklet]:
    """The tracklets of result ``rows``: each id cut at missing frames, jumps and contacts (module doc)."""
    cfg = config or ClosedSetConfig()
    rows = checked_rows(rows)
    if not len(rows):
        return []
    steps = row_steps(rows)
    typical = float(np.percentile(steps, 90)) if len(steps) else 0.0
    contact = _contact_frames(rows, cfg.contact_iou) if cfg.contact_iou is not None else np.zeros(len(rows), bool)
    out: list[Tracklet] = []
    for tid in np.unique(rows[:, 1]):
        sel = np.flatnonzero(rows[:, 1] == tid)
        sel = sel[np.argsort(rows[sel, 0], kind="stable")]
        r, touch = rows[sel], contact[sel]
        keep = np.r_[True, np.diff(r[:, 0]) > 0]  # one row per frame and id
        r, touch = r[keep], _fill_short(touch[keep], cfg.velocity_frames)
        step = np.linalg.norm(np.diff(row_centres(r), axis=0), axis=1)
        size = row_sizes(r)
        limit = np.maximum(cfg.jump * typical, cfg.jump_floor * np.minimum(size[:-1], size[1:]))
        cut = (np.diff(r[:, 0]) > 1) | (step > limit) | (touch[1:] != touch[:-1])
        for piece in np.split(np.arange(len(r)), np.flatnonzero(cut) + 1):
            out.append(Tracklet(r[piece], int(tid), bool(touch[piece].all())))
    out.sort(key=lambda t: (t.first, t.last))
    return out


def _end_state(rows: np.ndarray, k: int) -> tuple[np.ndarray, np.ndarray]:
    """Centre (px) of the last row and velocity (px/frame) over the last ``k`` rows."""
    c = row_centres(rows[-k:])
    f = rows[-k:, 0]
    v = (c[-1] - c[0]) / (f[-1] - f[0]) if len(f) > 1 and f[-1] > f[0] else np.zeros(2)
    return c[-1], v


def motion_scale(tracklets: list[Tracklet]) -> tuple[float, float, float]:
    """``(size px, speed px/frame, jitter px/frame²)`` of a sequence's tracklets: the mean box size √(w·h),
    the 90th-percentile step between consecutive rows and the median second difference of centres."""
    if not tracklets:
        return 1.0, 0.0, 0.0
    size = float(np.mean(row_sizes(np.vstack([t.rows for t in tracklets]))))
    steps = np.concatenate([np.linalg.norm(np.diff(row_centres(t.rows), axis=0), axis=1) for t in tracklets])
    speed = float(np.percentile(steps, 90)) if len(steps) else 0.0
    bends = np.concatenate([np.linalg.norm(np.diff(row_centres(t.rows), n=2, axis=0), axis=1) for t in tracklets])
    jitter = float(np.median(bends)) if len(bends) else speed
    return size, speed, jitter


LINK_BLOCK = 1 << 22  # tracklet end x start pairs scored at once by link_costs


def link_costs(tracklets: list[Tracklet], frame_rate: float,
               config: ClosedSetConfig | None = None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Candidate links ``(i, j, cost)``: tracklet ``j`` continues tracklet ``i`` (module doc, step 2)."""
    cfg = config or ClosedSetConfig()
    if not frame_rate > 0:
        raise ValueError(f"frame_rate must be > 0 frames/s, got {frame_rate}")
    n = len(tracklets)
    empty = (np.zeros(0, int), np.zeros(0, int), np.zeros(0))
    if n < 2:
        return empty
    max_gap = math.inf if math.isinf(cfg.max_gap_s) else round(cfg.max_gap_s * frame_rate)
    size, speed, jitter = motion_scale(tracklets)
    first = np.array([t.first for t in tracklets])
    last = np.array([t.last for t in tracklets])
    k = cfg.velocity_frames
    ends = [_end_state(t.rows, k) for t in tracklets]
    starts = [_end_state(t.rows[::-1], k) for t in tracklets]  # backwards in time
    c_end = np.array([e[0] for e in ends])
    v_end = np.array([e[1] for e in ends])
    c_start = np.array([s[0] for s in starts])
    v_start = np.array([s[1] for s in starts])
    source = np.array([t.source_id for t in tracklets])
    found = []
    step = max(1, LINK_BLOCK // n)  # ends scored a block at a time: memory linear in the tracklets
    for lo in range(0, n, step):
        rows = slice(lo, min(lo + step, n))
        gap = first[None, :] - last[rows, None]  # [i, j]: frames from the end of i to the start of j
        ii, jj = np.nonzero((gap >= 1) & (gap <= max_gap))
        g = gap[ii, jj]
        ii += lo
        found.append(_block_links(ii, jj, g, c_end, v_end, c_start, v_start, source, (size, speed, jitter), cfg))
    ii, jj, cost = (np.concatenate(x) for x in zip(*found))
    if not len(ii):
        return empty
    keep = _cheapest(ii, cost, cfg.candidates) | _cheapest(jj, cost, cfg.candidates)
    return ii[keep], jj[keep], cost[keep]


def _block_links(ii: np.ndarray, jj: np.ndarray, gap: np.ndarray, c_end: np.ndarray, v_end: np.ndarray,
                 c_start: np.ndarray, v_start: np.ndarray, source: np.ndarray, scale: tuple[float, float, float],
                 cfg: ClosedSetConfig) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """:func:`link_costs` of the pairs ``(ii, jj)`` ``gap`` frames apart: those within ``max_z``, and of them the
    ``candidates`` cheapest per end and per start (a superset of the whole problem's cheapest)."""
    size, speed, jitter = scale
    g = gap.astype(float)
    # two motion hypotheses: constant velocity over the whole gap (spread grows with the jitter), or
    # holding still (spread grows with the speed); each scored as a 2-D Gaussian negative log-likelihood
    base = cfg.pos_sigma * size
    forward = np.linalg.norm(c_end[ii] + v_end[ii] * g[:, None] - c_start[jj], axis=1)
    backward = np.linalg.norm(c_start[jj] + v_start[jj] * g[:, None] - c_end[ii], axis=1)
    spread_v = base + jitter * g
    spread_h = base + speed * g
    z_v = (forward + backward) / 2 / spread_v
    z_h = np.linalg.norm(c_end[ii] - c_start[jj], axis=1) / spread_h
    nll = np.minimum(0.5 * z_v**2 + 2 * np.log(spread_v / base), 0.5 * z_h**2 + 2 * np.log(spread_h / base))
    z = np.minimum(z_v, z_h)
    ok = z <= cfg.max_z
    ii, jj, nll, gap = ii[ok], jj[ok], nll[ok], gap[ok]
    cut = (source[ii] == source[jj]) & (gap == 1)  # a cut inside one input track (a contact)
    cost = np.where(cut, cfg.continue_cost, cfg.link_cost) + nll
    keep = _cheapest(ii, cost, cfg.candidates) | _cheapest(jj, cost, cfg.candidates)
    return ii[keep], jj[keep], cost[keep]


def _cheapest(group: np.ndarray, cost: np.ndarray, k: int) -> np.ndarray:
    """Mask of the ``k`` cheapest entries of every group."""
    order = np.lexsort((cost, group))
    g = group[order]
    start = np.r_[0, np.flatnonzero(np.diff(g)) + 1]
    rank = np.arange(len(g)) - np.repeat(start, np.diff(np.r_[start, len(g)]))
    mask = np.zeros(len(group), dtype=bool)
    mask[order[rank < k]] = True
    return mask
