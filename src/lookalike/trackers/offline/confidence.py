"""A probability per result row that its identity is right, from the rows alone (any tracker, online or offline,
open or closed set), and the frame ranges where an identity is doubtful. Rows are MOTChallenge ``(k, 10)``: 1-based
frame, id, ``x, y, w, h`` px, ...; ``frame_rate`` in frames/s sets the one-second window ``W`` of the features.

The features (:data:`FEATURES`, per row; size ``s = sqrt(w h)`` px): ``crowd_now``, the distance to the nearest other
identity's box centre in the frame over the mean of the two sizes, clipped to [0, 2]; ``crowd_window``, its minimum
over the identity's rows within ±W frames; ``since`` and ``until``, log(1 + seconds) from the identity's start or last
gap and to its end or next gap (clipped at 30 s); ``length``, log(1 + the identity's rows in seconds, clipped at
300 s); ``jump``, the largest |log| size ratio of consecutive rows within ±W frames (clipped at 1). A logistic model
maps them to a probability; :data:`COEFFICIENTS` were fitted by ``research/confidence/fit.py`` as
``research/confidence/rule.md`` fixes it. Rows of the offline closed set that learned a look may add one more term,
:data:`LOOK_COEFFICIENT` times each row's look margin (:func:`~lookalike.trackers.offline.appearance.look_margins`;
``research/confidence/look-rule.md``)."""

from __future__ import annotations

import numpy as np

FEATURES = ("crowd_now", "crowd_window", "since", "until", "length", "jump")
# Intercept, then one weight per feature of FEATURES: L2-penalised logistic regression on the rows of boxtrack's
# default (online) results on mot15, pigs, mot17-synth and HexBug and of the offline closed set on pigs and HexBug,
# each dataset weighted equally (research/confidence/rule.md, fit-result.txt).
COEFFICIENTS = (0.4865, -0.2975, 0.4194, 0.7158, 0.7521, -0.2170, -3.3267)
LOOK_COEFFICIENT = 0.6797  # the look margin's weight, fitted on arenas and HexBug (research/confidence/look-rule.md)
DOUBTFUL_BELOW = 0.5  # a row is doubtful below this probability (research/confidence/rule.md)
_CROWD_CLIP, _EDGE_CLIP_S, _LENGTH_CLIP_S, _JUMP_CLIP = 2.0, 30.0, 300.0, 1.0
_PAIR_BUDGET = 1 << 22  # distances computed at once in crowd_now


def require_frame_rate(frame_rate: float) -> None:
    """``ValueError`` unless ``frame_rate`` (frames/s) is a finite number above 0."""
    if not np.isfinite(frame_rate) or frame_rate <= 0:
        raise ValueError(f"frame_rate must be > 0 frames/s, got {frame_rate}")


def _check(rows: np.ndarray, frame_rate: float) -> np.ndarray:
    rows = np.asarray(rows, dtype=float)
    if rows.ndim != 2 or (len(rows) and rows.shape[1] < 6):
        raise ValueError(f"rows: expected (k, >= 6) MOTChallenge rows, got shape {rows.shape}")
    require_frame_rate(frame_rate)
    return rows


def window_frames(frame_rate: float) -> int:
    """The features' and ranges' window ``W``: one second in frames (at least 1)."""
    return max(1, int(round(frame_rate)))


def _crowding(frame: np.ndarray, centre: np.ndarray, size: np.ndarray) -> np.ndarray:
    """Per row the nearest other row's centre distance in its frame over the mean size (clipped)."""
    out = np.full(len(frame), _CROWD_CLIP)
    order = np.argsort(frame, kind="stable")
    f = frame[order]
    starts = np.flatnonzero(np.r_[True, f[1:] != f[:-1]])
    counts = np.diff(np.r_[starts, len(f)])
    rank = np.arange(len(f)) - np.repeat(starts, counts)
    width = int(counts.max())
    if width < 2:
        return out
    block = np.repeat(np.arange(len(starts)), counts)
    c = np.full((len(starts), width, 2), np.nan)
    s = np.full((len(starts), width), np.nan)
    c[block, rank], s[block, rank] = centre[order], size[order]
    near = np.full((len(starts), width), np.inf)
    step = max(1, _PAIR_BUDGET // (width * width))
    for a in range(0, len(starts), step):
        d = np.linalg.norm(c[a:a + step, :, None] - c[a:a + step, None], axis=3)
        d /= (s[a:a + step, :, None] + s[a:a + step, None]) / 2
        d[:, np.arange(width), np.arange(width)] = np.inf
        near[a:a + step] = np.fmin.reduce(np.where(np.isnan(d), np.inf, d), axis=2)
    out[order] = np.minimum(near[block, rank], _CROWD_CLIP)
    return out


def _windowed(values: np.ndarray, frames: np.ndarray, half: int, fill: float, reduce: str) -> np.ndarray:
    """``reduce`` (min or max) of one identity's ``values`` over its rows within ±``half`` frames (sorted frames)."""
    span = int(frames[-1] - frames[0]) + 1
    dense = np.full(span + 2 * half, fill)
    dense[(frames - frames[0]).astype(int) + half] = values
    view = np.lib.stride_tricks.sliding_window_view(dense, 2 * half + 1)
    picked = view.min(axis=1) if reduce == "min" else view.max(axis=1)
    result: np.ndarray = picked[(frames - frames[0]).astype(int)]
    return result


def row_features(rows: np.ndarray, frame_rate: float) -> np.ndarray:
    """``(k, 6)`` features of :data:`FEATURES` per row, in the rows' order."""
    rows = _check(rows, frame_rate)
    out = np.zeros((len(rows), len(FEATURES)))
    if not len(rows):
        return out
    frame, ids = rows[:, 0].astype(np.int64), rows[:, 1].astype(np.int64)
    wh = np.nan_to_num(np.maximum(rows[:, 4:6], 1.0), nan=1.0)
    size = np.sqrt(wh[:, 0] * wh[:, 1])
    centre = np.nan_to_num(rows[:, 2:4] + wh / 2)
    crowd = _crowding(frame, centre, size)
    out[:, 0] = crowd
    half = window_frames(frame_rate)
    order = np.lexsort((frame, ids))
    bounds = np.flatnonzero(np.r_[True, ids[order][1:] != ids[order][:-1], True])
    for a, b in zip(bounds[:-1].tolist(), bounds[1:].tolist()):
        sel = order[a:b]
        f = frame[sel]
        out[sel, 1] = _windowed(crowd[sel], f, half, np.inf, "min")
        new_run = np.r_[True, np.diff(f) > 1]
        run = np.cumsum(new_run) - 1
        run_first = f[new_run][run]
        run_last = f[np.r_[new_run[1:], True]][run]
        out[sel, 2] = np.log1p(np.minimum((f - run_first) / frame_rate, _EDGE_CLIP_S))
        out[sel, 3] = np.log1p(np.minimum((run_last - f) / frame_rate, _EDGE_CLIP_S))
        out[sel, 4] = np.log1p(min(len(sel) / frame_rate, _LENGTH_CLIP_S))
        jumps = np.r_[0.0, np.abs(np.diff(np.log(size[sel])))]
        out[sel, 5] = np.minimum(_windowed(jumps, f, half, 0.0, "max"), _JUMP_CLIP)
    return out


def logistic(features: np.ndarray, coefficients: tuple[float, ...] | np.ndarray = COEFFICIENTS) -> np.ndarray:
    """``(k,)`` probabilities of ``(k, m)`` features under ``coefficients`` (intercept, then ``m`` weights)."""
    coef = np.asarray(coefficients, dtype=float)
    z = coef[0] + np.asarray(features, dtype=float) @ coef[1:]
    result: np.ndarray = 1.0 / (1.0 + np.exp(-np.clip(z, -50.0, 50.0)))
    return result


def assignment_confidence(rows: np.ndarray, frame_rate: float,
                          coefficients: tuple[float, ...] | np.ndarray = COEFFICIENTS,
                          look: np.ndarray | None = None) -> np.ndarray:
    """``(k,)`` probability in [0, 1] that each row's identity is right, in the rows' order; ``look``: each row's
    look margin (``(k,)``, NaN where there is none) when the closed set learned a look."""
    features, coef = row_features(rows, frame_rate), np.asarray(coefficients, dtype=float)
    if look is not None:
        look = np.asarray(look, dtype=float)
        if look.shape != (len(features),):
            raise ValueError(f"look: expected ({len(features)},), got shape {look.shape}")
        features, coef = np.column_stack([features, np.nan_to_num(look)]), np.r_[coef, LOOK_COEFFICIENT]
    return logistic(features, coef)


def by_frame_and_id(rows: np.ndarray, keyed: np.ndarray) -> np.ndarray:
    """Per row of ``rows`` (1-based frame, id, ...) the value of the row of ``keyed`` ``(m, 3)`` (frame, id, value)
    with its frame and id; NaN where there is none."""
    out = np.full(len(rows), np.nan)
    if not len(keyed) or not len(rows):
        return out
    lo = min(rows[:, 1].min(), keyed[:, 1].min())  # (ids made >= 0, so that each (frame, id) has its own key)
    width = max(rows[:, 1].max(), keyed[:, 1].max()) - lo + 1
    key, at = keyed[:, 0] * width + keyed[:, 1] - lo, rows[:, 0] * width + rows[:, 1] - lo
    order = np.argsort(key, kind="stable")
    pos = np.clip(np.searchsorted(key[order], at), 0, len(key) - 1)
    found = key[order][pos] == at
    out[found] = keyed[order][pos[found], 2]
    return out


def doubtful_ranges(rows: np.ndarray, confidence: np.ndarray, frame_rate: float,
                    threshold: float = DOUBTFUL_BELOW) -> dict[int, list[tuple[int, int]]]:
    """Per id, inclusive ``(first, last)`` frame ranges of its rows with ``confidence`` below ``threshold``, frames
    at most one second (:func:`window_frames`) apart merged; ids without one are left out."""
    rows = _check(rows, frame_rate)
    confidence = np.asarray(confidence, dtype=float)
    if confidence.shape != (len(rows),):
        raise ValueError(f"confidence: expected ({len(rows)},), got shape {confidence.shape}")
    if np.isnan(confidence).any():
        raise ValueError(f"confidence: NaN at row {int(np.flatnonzero(np.isnan(confidence))[0])}")
    low = rows[confidence < threshold][:, :2].astype(np.int64)
    low = low[np.lexsort((low[:, 0], low[:, 1]))]
    if not len(low):
        return {}
    half = window_frames(frame_rate)
    # a range starts at an id's first low row or after more than `half` frames without one
    firsts = np.flatnonzero(np.r_[True, (low[1:, 1] != low[:-1, 1]) | (low[1:, 0] - low[:-1, 0] > half)])
    lasts = np.r_[firsts[1:] - 1, len(low) - 1]
    out: dict[int, list[tuple[int, int]]] = {}
    for i, a, b in zip(low[firsts, 1].tolist(), low[firsts, 0].tolist(), low[lasts, 0].tolist()):
        out.setdefault(i, []).append((a, b))
    return out


def describe_ranges(ranges: dict[int, list[tuple[int, int]]], max_ids: int = 8, max_ranges: int = 4) -> str:
    """One line: ``doubtful: id 3 frames 120-160, 410-433; id 7 ...``, the ids with the most doubtful frames first
    (at most ``max_ids``, each with its first ``max_ranges`` ranges); ``doubtful: none`` when empty."""
    if not ranges:
        return "doubtful: none"
    frames = {i: sum(b - a + 1 for a, b in r) for i, r in ranges.items()}
    shown = sorted(sorted(ranges, key=lambda i: -frames[i])[:max_ids])
    parts = []
    for i in shown:
        spans = [f"{a}-{b}" if b > a else f"{a}" for a, b in ranges[i][:max_ranges]]
        more = len(ranges[i]) - max_ranges
        parts.append(f"id {i} frames {', '.join(spans)}" + (f" (+{more} more)" if more > 0 else ""))
    rest = len(ranges) - len(shown)
    return "doubtful: " + "; ".join(parts) + (f"; {rest} more id{'s' if rest > 1 else ''}" if rest > 0 else "")
