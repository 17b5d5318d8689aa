"""The numba kernels of :mod:`lookalike.trackers.kernels.boxtrack` (imported only when numba is installed).

Each does BoxTrack's numpy-path operations one track or pair at a time in the same order (``fastmath`` off), so rows are
bit for bit the same. State columns ``x (24, k)``: :class:`~lookalike.motion.spaces.BoxCXCYWH`'s column form (pixels,
pixels/frame)."""

from __future__ import annotations

import numpy as np

from lookalike._compiled import exact_jit

_jit = exact_jit()


@_jit
def _maximum(a: float, b: float) -> float:
    """``np.maximum``'s number: NaN when either is NaN (the first when both are)."""
    return a if (a >= b or a != a) else b


@_jit
def _minimum(a: float, b: float) -> float:
    """``np.minimum``'s number: NaN when either is NaN (the first when both are)."""
    return a if (a <= b or a != a) else b


@_jit
def _iou(ax: float, ay: float, aw: float, ah: float, bx: float, by: float, bw: float, bh: float) -> float:
    """``iou_columns``' number for one pair of boxes (left, top, width, height; pixels)."""
    sx = _minimum(ax + aw, bx + bw)
    sx = sx - _maximum(ax, bx)
    sx = _maximum(sx, 0.0)
    sy = _minimum(ay + ah, by + bh)
    sy = sy - _maximum(ay, by)
    sy = _maximum(sy, 0.0)
    inter = sx * sy
    union = aw * ah + bw * bh
    union = union - inter
    if union > 0:
        return inter / union  # type: ignore[no-any-return, unused-ignore]
    return 0.0


@_jit
def _add_noise(x: np.ndarray, i: int, row: int, q_w: float, q_h: float) -> None:
    """Add the process noise ``q_w`` (to the x and width rows) and ``q_h`` (y and height) to the four
    variance rows of track ``i`` of ``x`` from ``row`` on (pixels², per the rows' units)."""
    x[row, i] += q_w
    x[row + 1, i] += q_h
    x[row + 2, i] += q_w
    x[row + 3, i] += q_h


@_jit
def _predict_column(x: np.ndarray, i: int, steps: float, var_steps: float, still: bool, pos2: float,
                    vel2: float) -> None:
    """``BoxCXCYWH.predict_columns``' numbers for the track ``i`` of ``x``, its velocities dropped first when
    ``still``."""
    if still:
        x[4, i] = 0.0
        x[5, i] = 0.0
        x[6, i] = 0.0
        x[7, i] = 0.0
    sw = _maximum(x[2, i], 1.0)
    sh = _maximum(x[3, i], 1.0)
    var_w = sw * sw
    var_h = sh * sh
    if steps == 1.0:  # x * 1.0 == x: the numpy path skips the multiplications
        if x[2, i] + x[6, i] <= 1.0:
            x[6, i] = 0.0
        if x[3, i] + x[7, i] <= 1.0:
            x[7, i] = 0.0
        for r in range(4):
            x[r, i] += x[4 + r, i]
            x[8 + r, i] += x[16 + r, i]
            x[12 + r, i] += x[20 + r, i]
            x[16 + r, i] += x[20 + r, i]
            x[8 + r, i] += x[12 + r, i]
    else:
        var_w = var_w * var_steps
        var_h = var_h * var_steps
        if x[2, i] + x[6, i] * steps <= 1.0:
            x[6, i] = 0.0
        if x[3, i] + x[7, i] * steps <= 1.0:
            x[7, i] = 0.0
        for r in range(4):
            x[r, i] += steps * x[4 + r, i]
            x[8 + r, i] += steps * x[16 + r, i]
            p22 = steps * x[20 + r, i]
            x[12 + r, i] += p22
            x[16 + r, i] += p22
            x[8 + r, i] += steps * x[12 + r, i]
    _add_noise(x, i, 8, pos2 * var_w, pos2 * var_h)  # the positions' variances
    _add_noise(x, i, 20, vel2 * var_w, vel2 * var_h)  # the velocities'


@_jit
def advance(x: np.ndarray, steps: float, var_steps: float, unseen_s: np.ndarray, coast_s: float, pos2: float,
            vel2: float, prev: np.ndarray, det: np.ndarray, min_iou: float) -> tuple[np.ndarray, int]:
    """Predict the tracks of ``x`` by ``steps`` frames in place (velocities of tracks unseen ``coast_s`` seconds or more
    dropped first; ``var_steps = max(steps, 0)``; ``pos2``, ``vel2`` the squared noise fractions), then the IoU matrix
    ``(k, n)`` of the predicted boxes against the detections ``det (n, 4)`` and the number of detections overlapping
    (IoU >= ``min_iou``) none of the previous frame's ``prev (p, 4)`` (all of them when ``p`` is 0)."""
    k = x.shape[1]
    for i in range(k):
        _predict_column(x, i, steps, var_steps, unseen_s[i] >= coast_s, pos2, vel2)
    n = det.shape[0]
    iou = np.empty((k, n))
    for i in range(k):
        w = _maximum(x[2, i], 1e-3)
        h = _maximum(x[3, i], 1e-3)
        left = x[0, i] - w / 2
        top = x[1, i] - h / 2
        for j in range(n):
            iou[i, j] = _iou(left, top, w, h, det[j, 0], det[j, 1], det[j, 2], det[j, 3])
    p = prev.shape[0]
    flicker = n
    if p:
        flicker = 0
        for j in range(n):
            seen = False
            for i in range(p):
                if _iou(prev[i, 0], prev[i, 1], prev[i, 2], prev[i, 3], det[j, 0], det[j, 1], det[j, 2],
                        det[j, 3]) >= min_iou:
                    seen = True
                    break
            if not seen:
                flicker += 1
    return iou, flicker


@_jit
def _eligible(stage: int, confirmed: bool, recent: bool, was_tracked: bool) -> bool:
    """Whether a track takes part in the IoU stage ``stage``: confirmed and recent, confirmed and not recent,
    confirmed and tracked in the previous frame (the low-score stage), tentative."""
    if stage == 0:
        return confirmed and recent
    if stage == 1:
        return confirmed and not recent
    if stage == 2:
        return confirmed and was_tracked
    return not confirmed


@_jit
def gated_stages(iou: np.ndarray, start: int, match_iou: float, low_iou: float, confirmed: np.ndarray,
                 misses: np.ndarray, recent: int, unseen_s: np.ndarray, score: np.ndarray, high_score: float,
                 det_of_track: np.ndarray, free: np.ndarray, stage_of_track: np.ndarray) -> int:
    """BoxTrack's four IoU stages from ``start`` on, each gated by its IoU (``match_iou``; ``low_iou`` for the low-score
    stage): a stage whose allowed pairs (eligible track unmatched, eligible detection free) are disjoint takes them all,
    as ``run_stage`` does. Returns the first stage whose pairs compete (its costs decide; nothing of it done), else 4
    when the re-identification stage has an unmatched confirmed track and a free confident detection, else 5."""
    k, n = iou.shape
    rows = np.empty(min(k, n), np.int64)
    cols = np.empty(min(k, n), np.int64)
    row_used = np.zeros(k, np.bool_)
    col_used = np.zeros(n, np.bool_)
    for s in range(start, 4):
        low = s == 2
        thr = low_iou if low else match_iou
        count = 0
        for i in range(k):
            if det_of_track[i] >= 0:
                continue
            if not _eligible(s, confirmed[i], misses[i] <= recent, unseen_s[i] == 0):
                continue
            for j in range(n):
                if not free[j] or (score[j] >= high_score) == low:
                    continue
                if iou[i, j] >= thr:
                    if row_used[i] or col_used[j]:
                        return s  # competing pairs: nothing of this stage is done
                    row_used[i] = True
                    col_used[j] = True
                    rows[count] = i
                    cols[count] = j
                    count += 1
        for m in range(count):
            i, j = rows[m], cols[m]
            det_of_track[i] = j
            free[j] = False
            stage_of_track[i] = s
            row_used[i] = False
            col_used[j] = False
    track_left = False
    for i in range(k):
        if confirmed[i] and det_of_track[i] < 0:
            track_left = True
            break
    if track_left:
        for j in range(n):
            if free[j] and score[j] >= high_score:
                return 4
    return 5


@_jit
def correct(x: np.ndarray, det_of_track: np.ndarray, det: np.ndarray, pos_noise: float, confirmed: np.ndarray,
            misses: np.ndarray, unseen_s: np.ndarray, hits: np.ndarray, record: bool, dt: float, n_init: int,
            first: bool, fit: np.ndarray, back: np.ndarray) -> tuple[int, int]:
    """Kalman update in place of the tracks of ``x`` matched (``det_of_track``) to detections ``det (n, 4)`` (xywh,
    pixels), with hit counts; with ``record`` also ``misses``, ``unseen_s`` (+ ``dt`` seconds) and confirmation
    (``n_init`` hits, any hit in the ``first`` frame). Writes the confirmed matched tracks' centre innovations and
    variances into ``fit (4, k)`` and returning tracks' misses into ``back (k,)``; returns both counts."""
    k = x.shape[1]
    n_fit = 0
    n_back = 0
    for i in range(k):
        d = det_of_track[i]
        if d < 0:
            hits[i] = 0
            if record:
                misses[i] += 1
                unseen_s[i] = unseen_s[i] + dt
                if n_init <= 0:
                    confirmed[i] = True
            continue
        hits[i] += 1
        w = det[d, 2]
        h = det[d, 3]
        z0 = det[d, 0] + w / 2.0
        z1 = det[d, 1] + h / 2.0
        std_w = pos_noise * w
        std_h = pos_noise * h
        r_w = std_w * std_w
        r_h = std_h * std_h
        s0 = x[8, i] + r_w
        s1 = x[9, i] + r_h
        s2 = x[10, i] + r_w
        s3 = x[11, i] + r_h
        i0 = z0 - x[0, i]
        i1 = z1 - x[1, i]
        i2 = w - x[2, i]
        i3 = h - x[3, i]
        if confirmed[i]:
            fit[0, n_fit] = i0
            fit[1, n_fit] = i1
            fit[2, n_fit] = s0
            fit[3, n_fit] = s1
            n_fit += 1
            if misses[i] > 0:
                back[n_back] = misses[i]
                n_back += 1
        for r in range(4):
            s = s0 if r == 0 else s1 if r == 1 else s2 if r == 2 else s3
            inn = i0 if r == 0 else i1 if r == 1 else i2 if r == 2 else i3
            p11 = x[8 + r, i]
            p12 = x[12 + r, i]
            p21 = x[16 + r, i]
            p22 = x[20 + r, i]
            g1 = p11 / s
            g2 = p21 / s
            x[r, i] += g1 * inn
            x[4 + r, i] += g2 * inn
            x[8 + r, i] = p11 - g1 * p11
            x[12 + r, i] = p12 - g1 * p21
            x[16 + r, i] = p21 - g2 * p11
            x[20 + r, i] = p22 - g2 * p21
        if record:
            misses[i] = 0
            unseen_s[i] = 0.0
            if hits[i] >= n_init or first:
                confirmed[i] = True
    return n_fit, n_back


@_jit
def report(mean: np.ndarray, ids: np.ndarray, confirmed: np.ndarray, det_of_track: np.ndarray, born: np.ndarray,
           det_idx: np.ndarray, misses: np.ndarray, present: np.ndarray, interval: float, unseen_s: np.ndarray,
           tentative_s: float, limit_s: float, closed: bool, alive: np.ndarray
           ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray, int]:
    """The frame's report: confirmed tracks matched this frame (then ``born`` rows) at their filtered box, then
    confirmed tracks missed ``m`` frames with ``present[min(m, L)]`` (the coasting table) at their box, detection index
    -1; ``det_idx`` maps kept detections to the frame's (empty: identity). Returns ids, status, boxes ``(m, 4)`` (xywh,
    sizes floored at 1e-3 pixels), velocities ``(m, 2)`` (pixels per ``interval``), detection indices and the number
    alive (``alive`` written: tentative unseen <= ``tentative_s``, confirmed <= ``limit_s`` or all when ``closed``)."""
    k = len(ids)
    n_old = len(det_of_track)
    last = len(present) - 1
    order = np.empty(k, np.int64)
    original = np.empty(k, np.int64)
    m = 0
    for i in range(k):
        d = det_of_track[i] if i < n_old else born[i - n_old]
        if confirmed[i] and d >= 0:
            order[m] = i
            original[m] = det_idx[d] if len(det_idx) else d
            m += 1
    for i in range(k):
        d = det_of_track[i] if i < n_old else born[i - n_old]
        if confirmed[i] and d < 0:
            j = misses[i]
            if present[last if j < 0 or j > last else j]:
                order[m] = i
                original[m] = -1
                m += 1
    out_ids = np.empty(m, np.int64)
    status = np.ones(m, np.int8)
    boxes = np.empty((m, 4))
    velocity = np.empty((m, 2))
    for r in range(m):
        i = order[r]
        out_ids[r] = ids[i]
        w = _maximum(mean[i, 2], 1e-3)
        h = _maximum(mean[i, 3], 1e-3)
        boxes[r, 0] = mean[i, 0] - w / 2
        boxes[r, 1] = mean[i, 1] - h / 2
        boxes[r, 2] = w
        boxes[r, 3] = h
        velocity[r, 0] = mean[i, 4] / interval
        velocity[r, 1] = mean[i, 5] / interval
    n_alive = 0
    for i in range(k):
        tentative = unseen_s[i] <= tentative_s
        if closed:
            keep = confirmed[i] or tentative
        elif confirmed[i]:
            keep = unseen_s[i] <= limit_s
        else:
            keep = tentative
        alive[i] = keep
        if keep:
            n_alive += 1
    return out_ids, status, boxes, velocity, original[:m].copy(), n_alive
