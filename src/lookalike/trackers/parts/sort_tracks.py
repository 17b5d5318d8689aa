"""SORT's tracks as one array: its Kalman filter (``[u, v, s, r, u', v', s']``, constant velocity, diagonal noise) keeps
a block-diagonal covariance, so a track is 20 numbers ``[x1 (4) | x2 (4) | p11 (4) | p12 (4) | p22 (4)]`` updated
element-wise (the full 7×7 filter to rounding). Association is the reference's IoU matching; from :data:`SPARSE_FROM`
pairs only boxes whose x-ranges overlap are compared, solved per connected component."""

from __future__ import annotations

import numpy as np

R = np.array([1.0, 1.0, 10.0, 10.0])
"""Measurement noise variances of ``[u, v, s, r]`` (pixels², pixels⁴, 1)."""
P0_POSITION = np.array([10.0, 10.0, 10.0, 10.0])
P0_VELOCITY = np.array([1e4, 1e4, 1e4, 0.0])
Q_POSITION = np.array([1.0, 1.0, 1.0, 1.0])
Q_VELOCITY = np.array([1e-2, 1e-2, 1e-4, 0.0])
WIDTH = 20
SPARSE_FROM = 30_000
"""Detections × tracks from which the sparse IoU and the per-component matching are used."""

_transitions: dict[float, tuple[np.ndarray, np.ndarray]] = {}


def transition(steps: float) -> tuple[np.ndarray, np.ndarray]:
    """``(M, b)`` with ``state @ M + b`` the prediction ``steps`` frames ahead (``F P Fᵀ + Q·steps``)."""
    found = _transitions.get(steps)
    if found is not None:
        return found
    dt = float(steps)
    M = np.eye(WIDTH)
    eye = np.eye(4)
    M[4:8, 0:4] = dt * eye  # x1 += dt x2
    M[12:16, 8:12] = 2 * dt * eye  # p11 += 2 dt p12 + dt² p22
    M[16:20, 8:12] = dt * dt * eye
    M[16:20, 12:16] = dt * eye  # p12 += dt p22
    b = np.zeros(WIDTH)
    b[8:12] = dt * Q_POSITION
    b[16:20] = dt * Q_VELOCITY
    if len(_transitions) < 64:
        _transitions[steps] = (M, b)
    return M, b


def initial_state(z: np.ndarray) -> np.ndarray:
    """``(n, 20)`` new tracks at measurements ``z (n, 4)`` ``[u, v, s, r]``, zero velocity."""
    out = np.zeros((len(z), WIDTH))
    out[:, 0:4] = z
    out[:, 8:12] = P0_POSITION
    out[:, 16:20] = P0_VELOCITY
    return out


def kalman_update(state: np.ndarray, z: np.ndarray) -> np.ndarray:
    """Posterior ``(k, 20)`` of tracks ``state (k, 20)`` given measurements ``z (k, 4)``."""
    k = len(state)
    out: np.ndarray = state.copy()
    cov = state[:, 8:16].reshape(k, 2, 4)  # p11, p12
    gain = cov / (state[:, 8:12] + R)[:, None, :]  # k1 = p11 / S, k2 = p12 / S
    innovation = z - state[:, 0:4]
    out[:, 0:8] += (gain * innovation[:, None, :]).reshape(k, 8)
    out[:, 16:20] -= gain[:, 1] * state[:, 12:16]  # p22 -= k2 p12
    out[:, 8:16] -= (cov * gain[:, 0:1]).reshape(k, 8)  # p11, p12 *= 1 - k1
    return out


def measure(xyxy: np.ndarray) -> np.ndarray:
    """``[u, v, s, r]`` of boxes ``(n, 4)`` left/top/right/bottom (the reference's conversion)."""
    size = xyxy[:, 2:4] - xyxy[:, 0:2]
    z = np.empty((len(xyxy), 4))
    np.add(xyxy[:, 0:2], size / 2.0, out=z[:, 0:2])
    np.multiply(size[:, 0], size[:, 1], out=z[:, 2])
    np.divide(size[:, 0], size[:, 1], out=z[:, 3])
    return z


def box_corners(state: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(k, 4)`` left/top/right/bottom boxes of tracks with positive ``s·r`` and their areas
    ``(k,)`` computed from the corners (as the reference's IoU does)."""
    half = np.empty((len(state), 2))
    np.sqrt(state[:, 2] * state[:, 3], out=half[:, 0])
    np.divide(state[:, 2], half[:, 0], out=half[:, 1])
    half /= 2.0
    out = np.empty((len(state), 4))
    np.subtract(state[:, 0:2], half, out=out[:, 0:2])
    np.add(state[:, 0:2], half, out=out[:, 2:4])
    size = out[:, 2:4] - out[:, 0:2]
    return out, size[:, 0] * size[:, 1]


def box_xywh(state: np.ndarray) -> np.ndarray:
    """``(k, 4)`` left/top/width/height boxes of tracks with positive ``s·r``."""
    out = np.empty((len(state), 4))
    np.sqrt(state[:, 2] * state[:, 3], out=out[:, 2])
    np.divide(state[:, 2], out[:, 2], out=out[:, 3])
    np.subtract(state[:, 0:2], out[:, 2:4] / 2.0, out=out[:, 0:2])
    return out


def iou_dense(det: np.ndarray, det_area: np.ndarray, trk: np.ndarray, trk_area: np.ndarray) -> np.ndarray:
    """IoU ``(n, k)`` of ``xyxy`` boxes with their areas, as the reference computes it (tracks have
    positive area, so no union is 0)."""
    lo = np.maximum(det[:, None, 0:2], trk[None, :, 0:2])
    size = np.minimum(det[:, None, 2:4], trk[None, :, 2:4])
    size -= lo
    np.maximum(size, 0.0, out=size)
    inter = size[:, :, 0] * size[:, :, 1]
    union = det_area[:, None] + trk_area
    union -= inter
    out: np.ndarray = inter / union
    return out


def _solve_dense(iou: np.ndarray, threshold: float) -> tuple[np.ndarray, np.ndarray]:
    above = iou > threshold
    if above.sum(axis=1).max() == 1 and above.sum(axis=0).max() == 1:
        rows, cols = np.nonzero(above)
    else:
        from lookalike._lsap import linear_sum_assignment

        rows, cols = linear_sum_assignment(-iou)
    keep = iou[rows, cols] >= threshold
    return rows[keep], cols[keep]


def overlapping_pairs(det: np.ndarray, trk: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Every detection/track pair of ``xyxy`` boxes with a positive IoU: ``(det, track, iou)``,
    found by sorting the detections by their left edge and comparing only overlapping x-ranges."""
    order = np.argsort(det[:, 0], kind="stable")
    left = det[order, 0]
    widest = float((det[:, 2] - det[:, 0]).max())
    lo = np.searchsorted(left, trk[:, 0] - widest, side="left")
    hi = np.searchsorted(left, trk[:, 2], side="left")
    count = np.maximum(hi - lo, 0)
    total = int(count.sum())
    t_idx = np.repeat(np.arange(len(trk)), count)
    offset = np.arange(total) - np.repeat(np.cumsum(count) - count, count)
    d_idx = order[np.repeat(lo, count) + offset]
    d, t = det[d_idx], trk[t_idx]
    w = np.minimum(d[:, 2], t[:, 2]) - np.maximum(d[:, 0], t[:, 0])
    h = np.minimum(d[:, 3], t[:, 3]) - np.maximum(d[:, 1], t[:, 1])
    hit = (w > 0) & (h > 0)
    d_idx, t_idx, d, t = d_idx[hit], t_idx[hit], d[hit], t[hit]
    wh = w[hit] * h[hit]
    union = (d[:, 2] - d[:, 0]) * (d[:, 3] - d[:, 1]) + (t[:, 2] - t[:, 0]) * (t[:, 3] - t[:, 1])
    union -= wh
    return d_idx, t_idx, wh / union


def _solve_sparse(d_idx: np.ndarray, t_idx: np.ndarray, iou: np.ndarray, n_det: int, n_trk: int,
                  threshold: float) -> tuple[np.ndarray, np.ndarray]:
    above = iou > threshold
    if above.any():
        per_det = np.bincount(d_idx[above], minlength=n_det)
        per_trk = np.bincount(t_idx[above], minlength=n_trk)
        if per_det.max() == 1 and per_trk.max() == 1:
            order = np.argsort(d_idx[above], kind="stable")
            return d_idx[above][order], t_idx[above][order]
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    from lookalike._lsap import linear_sum_assignment

    graph = coo_matrix((np.ones(len(iou)), (d_idx, n_det + t_idx)), shape=(n_det + n_trk,) * 2)
    _, label = connected_components(graph, directed=False)
    comp = label[d_idx]
    dets_in = np.bincount(label[:n_det], minlength=label.max() + 1)
    trks_in = np.bincount(label[n_det:], minlength=label.max() + 1)
    single = (dets_in[comp] == 1) & (trks_in[comp] == 1)
    rows, cols, values = [d_idx[single]], [t_idx[single]], [iou[single]]
    multi = ~single
    if multi.any():
        md, mt, mv, mc = d_idx[multi], t_idx[multi], iou[multi], comp[multi]
        order = np.argsort(mc, kind="stable")
        md, mt, mv, mc = md[order], mt[order], mv[order], mc[order]
        bounds = np.flatnonzero(np.diff(mc)) + 1
        for sd, st, sv in zip(np.split(md, bounds), np.split(mt, bounds), np.split(mv, bounds)):
            ud, ld = np.unique(sd, return_inverse=True)
            ut, lt = np.unique(st, return_inverse=True)
            block = np.zeros((len(ud), len(ut)))
            block[ld, lt] = sv
            r, c = linear_sum_assignment(-block)
            rows.append(ud[r])
            cols.append(ut[c])
            values.append(block[r, c])
    r_all, c_all = np.concatenate(rows), np.concatenate(cols)
    keep = np.concatenate(values) >= threshold
    order = np.argsort(r_all[keep], kind="stable")
    return r_all[keep][order], c_all[keep][order]


def match(det: np.ndarray, det_area: np.ndarray, trk: np.ndarray, trk_area: np.ndarray,
          threshold: float) -> tuple[np.ndarray, np.ndarray]:
    """SORT's matching of detections to predicted tracks (both ``xyxy``, with their areas):
    ``(det indices, track indices)`` of the kept pairs, by detection."""
    n, k = len(det), len(trk)
    if n == 0 or k == 0:
        empty = np.zeros(0, dtype=np.intp)
        return empty, empty
    if n * k < SPARSE_FROM or threshold <= 0:
        return _solve_dense(iou_dense(det, det_area, trk, trk_area), threshold)
    d_idx, t_idx, iou = overlapping_pairs(det, trk)
    return _solve_sparse(d_idx, t_idx, iou, n, k, threshold)


class SortTracks:
    """SORT's live tracks: states ``(k, 20)``, ids, hit streaks and misses, advanced by :meth:`step`."""

    def __init__(self, max_age: int, min_hits: int, iou_threshold: float) -> None:
        self.max_age, self.min_hits, self.iou_threshold = max_age, min_hits, iou_threshold
        self.clear()

    def clear(self) -> None:
        """Forget every track; ids restart at 1."""
        self.state = np.zeros((0, WIDTH))
        self.ids = np.zeros(0, dtype=int)
        self.hits = np.zeros(0, dtype=int)  # the current streak of consecutive hits
        self.misses = np.zeros(0, dtype=int)  # frames since the last update
        self.next_id = 1
        self.frame_count = 0

    def __len__(self) -> int:
        return len(self.ids)

    def _keep(self, mask: np.ndarray) -> None:
        self.state, self.ids = self.state[mask], self.ids[mask]
        self.hits, self.misses = self.hits[mask], self.misses[mask]

    def _predict(self, steps: float) -> tuple[np.ndarray, np.ndarray]:
        """Predict every track ``steps`` frames ahead, drop those whose box became invalid; return
        the predicted ``xyxy`` boxes and their areas."""
        x = self.state
        shrinking = x[:, 2] + x[:, 6] <= 0
        if shrinking.any():  # keep the predicted area positive, as the reference
            x[shrinking, 6] = 0.0
        M, b = transition(steps)
        x = x @ M
        x += b
        self.state = x
        self.hits[self.misses > 0] = 0
        self.misses += 1
        valid = x[:, 2] * x[:, 3] > 0
        if not valid.all():
            self._keep(valid)
        return box_corners(self.state)

    def step(self, xywh: np.ndarray, steps: float) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray,
                                                            np.ndarray]:
        """Advance by ``steps`` frames and match detections ``xywh (n, 4)`` (pixels); return the
        reported tracks as ``(ids, confirmed, xywh, velocity in pixels/frame, detection index)``."""
        self.frame_count += 1
        n = len(xywh)
        det = xywh.copy()
        det[:, 2:] += xywh[:, :2]
        z = measure(det)
        d = np.zeros(0, dtype=np.intp)
        if len(self.ids):
            pred, pred_area = self._predict(steps)
            det_of_track = np.full(len(self.ids), -1)
            if n:
                d, t = match(det, z[:, 2], pred, pred_area, self.iou_threshold)
                det_of_track[t] = d
                self.state[t] = kalman_update(self.state[t], z[d])
                self.misses[t] = 0
                self.hits[t] += 1
        else:
            det_of_track = np.full(0, -1)
        if len(d) < n:
            free = np.ones(n, dtype=bool)
            free[d] = False
            new = free.nonzero()[0]
            m = len(new)
            self.state = np.concatenate([self.state, initial_state(z[new])])
            self.ids = np.concatenate([self.ids, np.arange(self.next_id, self.next_id + m)])
            self.next_id += m
            self.hits = np.concatenate([self.hits, np.zeros(m, dtype=int)])
            self.misses = np.concatenate([self.misses, np.zeros(m, dtype=int)])
            det_of_track = np.concatenate([det_of_track, new])
        shown = self.misses < 1
        if self.frame_count > self.min_hits:
            shown &= self.hits >= self.min_hits
        idx = shown.nonzero()[0]
        x = self.state[idx]
        out = (self.ids[idx], self.hits[idx] >= self.min_hits, box_xywh(x), x[:, 4:6], det_of_track[idx])
        alive = self.misses <= self.max_age
        if not alive.all():
            self._keep(alive)
        return out
