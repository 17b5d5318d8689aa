"""Ground-truth and result tables as :class:`SequenceData` under a benchmark's rules: ``"MOT16"``, ``"MOT17"`` and
``"MOT20"`` drop tracker boxes matched (IoU >= 0.5) to distractor classes, then keep considered pedestrians; ``"MOT15"``
drops ground truth with a zero consider flag; ``"custom"`` keeps everything."""

from __future__ import annotations

from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Literal, Protocol

import numpy as np

from lookalike.eval.data import Pairs, SequenceData
from lookalike.eval.matching import conflicted_frames, negated_matrices, solve_matrices
from lookalike.eval.similarity import pair_iou, point_similarity, rows_of
from lookalike.types._validate import first_fraction
from lookalike.types.mot_table import MotTable as MotTableData


class MotTable(Protocol):
    """What scoring needs of a table of boxes (:class:`lookalike.io.MotTable`): ``frame`` ``(n,)`` 1-based, ``xywh``
    ``(n, 4)`` px, ``conf`` (gt: the consider flag), ``extra`` ``(n, k)`` (MOT16+ gt: class first), ``path``."""

    @property
    def frame(self) -> np.ndarray: ...
    @property
    def track_id(self) -> np.ndarray: ...
    @property
    def xywh(self) -> np.ndarray: ...
    @property
    def conf(self) -> np.ndarray: ...
    @property
    def extra(self) -> np.ndarray: ...
    @property
    def path(self) -> Path | None: ...

    def __len__(self) -> int: ...


BENCHMARKS = ("MOT15", "MOT16", "MOT17", "MOT20", "custom")
_DISTRACTORS = {"MOT16": (2, 7, 8, 12), "MOT17": (2, 7, 8, 12), "MOT20": (2, 6, 7, 8, 12)}
_VALID_CLASSES = np.arange(1, 14)
_EPS = np.finfo(float).eps


def where(table: MotTable, row: int, name: str) -> str:
    """``path:line`` (or ``name row k``) of a table's 0-based ``row``, for error messages."""
    if table.path is None:
        return f"{name} row {row + 1}"
    from lookalike.io.rules import is_data_line, read_text

    try:
        lines = read_text(table.path).splitlines()
    except (OSError, ValueError):
        return f"{table.path} row {row + 1}"
    numbers = [i + 1 for i, ln in enumerate(lines) if is_data_line(ln)]
    return f"{table.path}:{numbers[row] if row < len(numbers) else '?'}"


def check_table(table: MotTable, num_frames: int, name: str, keep: np.ndarray | None = None) -> None:
    """``ValueError`` for a frame beyond ``num_frames`` or an id twice in one frame (among rows ``keep``)."""
    beyond = np.flatnonzero(table.frame > num_frames)
    if len(beyond):
        row = int(beyond[0])
        raise ValueError(f"{where(table, row, name)}: frame {int(table.frame[row])} is beyond the sequence "
                         f"length {num_frames}")
    kept = np.arange(len(table)) if keep is None else np.flatnonzero(keep)
    if len(kept) > 1:
        order = kept[np.lexsort((table.track_id[kept], table.frame[kept]))]
        same = (np.diff(table.frame[order]) == 0) & (np.diff(table.track_id[order]) == 0)
        if same.any():
            row = int(order[np.flatnonzero(same)[0] + 1])
            raise ValueError(f"{where(table, row, name)}: id {int(table.track_id[row])} appears twice in frame "
                             f"{int(table.frame[row])}")


def _bounds(frames: np.ndarray, num_frames: int) -> tuple[np.ndarray, np.ndarray]:
    order = np.argsort(frames, kind="stable")
    return order, np.searchsorted(frames[order], np.arange(1, num_frames + 2))


def _relabel(ids: list[np.ndarray]) -> tuple[list[np.ndarray], int]:
    if not ids:
        return [], 0
    flat, n = _relabel_flat(np.concatenate(ids))
    return list(np.split(flat, np.cumsum([len(i) for i in ids])[:-1])), n


def prepare_boxes(gt: MotTable, result: MotTable, *, num_frames: int | None = None,
                  benchmark: str = "MOT15") -> SequenceData:
    """Box sequences (IoU similarity) with ``benchmark`` rules over frames ``1 .. num_frames`` (default: the last)."""
    if benchmark not in BENCHMARKS:
        raise ValueError(f"benchmark must be one of {BENCHMARKS}, got {benchmark!r}")
    n = _num_frames(gt, result, num_frames)
    check_table(result, n, "result")
    distractors = _DISTRACTORS.get(benchmark)
    if distractors is not None:
        if gt.extra.shape[1] < 1:
            raise ValueError(f"{gt.path or 'gt'}: {benchmark} ground truth needs a class column (8th)")
        gt_class = gt.extra[:, 0].astype(int)
        bad = np.flatnonzero(~np.isin(gt_class, _VALID_CLASSES))
        if len(bad):
            raise ValueError(f"{where(gt, int(bad[0]), 'gt')}: unknown MOTChallenge class {gt_class[bad[0]]}")
        keep_gt = (gt.conf != 0) & (gt_class == 1)
    elif benchmark == "MOT15":
        gt_class, keep_gt = None, gt.conf != 0
    else:
        gt_class, keep_gt = None, np.ones(len(gt), bool)
    check_table(gt, n, "gt", keep_gt)
    g_order, g_bounds = _bounds(gt.frame, n)
    r_order, r_bounds = _bounds(result.frame, n)
    g = g_order[g_bounds[0] : g_bounds[n]]  # rows of frames 1..n, in frame order
    r = r_order[r_bounds[0] : r_bounds[n]]
    gb, rb = g_bounds - g_bounds[0], r_bounds - r_bounds[0]
    g_frame = gt.frame[g].astype(np.int64) - 1
    r_frame = result.frame[r].astype(np.int64) - 1
    gi, ri, sim = _overlapping_pairs(gt.xywh[g], g_frame, result.xywh[r], r_frame)
    keep_r = np.ones(len(r), bool)
    if distractors is not None and gt_class is not None:
        _drop_distractor_matches(keep_r, gi, ri, sim, g_frame, gb, rb, gt_class[g], distractors)
    keep_g = keep_gt[g]
    new_g = np.cumsum(keep_g) - 1
    new_r = np.cumsum(keep_r) - 1
    pk = keep_g[gi] & keep_r[ri]
    gi, ri, sim = gi[pk], ri[pk], sim[pk]
    gt_ids, n_gt = _relabel_flat(gt.track_id[g[keep_g]])
    tr_ids, n_tr = _relabel_flat(result.track_id[r[keep_r]])
    gt_det, tr_det = new_g[gi], new_r[ri]
    pair = Pairs(g_frame[gi], gt_det, tr_det, gt_ids[gt_det], tr_ids[tr_det], sim, len(gt_ids), len(tr_ids))
    frames = np.arange(n + 1)
    return SequenceData(np.searchsorted(g_frame[keep_g], frames), gt_ids,
                        np.searchsorted(r_frame[keep_r], frames), tr_ids, pair, n_gt, n_tr)


def _relabel_flat(ids: np.ndarray) -> tuple[np.ndarray, int]:
    unique, inverse = np.unique(ids, return_inverse=True)
    return inverse.astype(np.int64).ravel(), len(unique)


def _overlapping_pairs(a: np.ndarray, a_frame: np.ndarray, b: np.ndarray,
                       b_frame: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Every same-frame pair ``(i, j)`` of boxes ``a[i]``, ``b[j]`` (``(n, 4)`` xywh px, sorted 0-based frames) with a
    positive IoU (bit for bit :func:`box_iou`'s), sorted by ``i`` then ``j``, found by sorted left-edge look-ups."""
    empty = np.zeros(0, np.int64)
    if not len(a) or not len(b):
        return empty, empty, np.zeros(0)
    ax0, bx0 = a[:, 0], b[:, 0]
    lo = min(float(ax0.min()), float(bx0.min()))
    span = max(float((ax0 + a[:, 2]).max()), float((bx0 + b[:, 2]).max()), 0.0) - lo + 4.0
    a0, a1 = a_frame * span + (ax0 - lo), a_frame * span + (ax0 + a[:, 2] - lo) + 1.0
    b0, b1 = b_frame * span + (bx0 - lo), b_frame * span + (bx0 + b[:, 2] - lo) + 1.0
    parts_i, parts_j, parts_s = [], [], []
    # b's left edge in [a0, a1], then a's left edge in (b0, b1].
    searches: tuple[tuple[np.ndarray, np.ndarray, np.ndarray, Literal["left", "right"], bool], ...] = (
        (b0, a0, a1, "left", True), (a0, b0, b1, "right", False))
    for keys, start, stop, side, owner_is_a in searches:
        for owner, found in _ranges(keys, start, stop, side):
            i, j = (owner, found) if owner_is_a else (found, owner)
            iou = pair_iou(a[i], b[j])
            pos = (iou > 0) & (a_frame[i] == b_frame[j])
            parts_i.append(i[pos])
            parts_j.append(j[pos])
            parts_s.append(iou[pos])
    i, j, iou = np.concatenate(parts_i), np.concatenate(parts_j), np.concatenate(parts_s)
    srt = np.argsort(i * len(b) + j)
    return i[srt], j[srt], iou[srt]


_CHUNK = 1 << 15  # candidate pairs per batch: keeps the IoU temporaries in cache


def _ranges(keys: np.ndarray, start: np.ndarray, stop: np.ndarray,
            side: Literal["left", "right"]) -> Iterator[tuple[np.ndarray, np.ndarray]]:
    """Batches of about :data:`_CHUNK` ``(index into start, index into keys)`` of every key in ``[start, stop]``
    (``(start, stop]`` with ``side="right"``)."""
    order = np.argsort(keys, kind="stable")
    sorted_keys = keys[order]
    first = np.searchsorted(sorted_keys, start, side)
    count = np.maximum(np.searchsorted(sorted_keys, stop, "right") - first, 0)
    ends = np.cumsum(count)
    cuts = np.unique(np.concatenate([[0], np.searchsorted(ends, np.arange(_CHUNK, int(ends[-1]), _CHUNK)),
                                     [len(count)]]))
    for o0, o1 in zip(cuts[:-1].tolist(), cuts[1:].tolist()):
        c = count[o0:o1]
        owner = np.repeat(np.arange(o0, o1), c)
        offset = np.repeat(first[o0:o1] - (np.cumsum(c) - c), c)
        yield owner, order[offset + np.arange(len(owner))]


def _drop_distractor_matches(keep_r: np.ndarray, gi: np.ndarray, ri: np.ndarray, sim: np.ndarray,
                             g_frame: np.ndarray, gb: np.ndarray, rb: np.ndarray, classes: np.ndarray,
                             distractors: tuple[int, ...]) -> None:
    """Clear ``keep_r`` for tracker boxes matched (per-frame Hungarian, IoU >= 0.5) to a distractor ground-truth box."""
    strong = sim >= 0.5 - _EPS
    gi, ri, sim = gi[strong], ri[strong], sim[strong]
    frame = g_frame[gi]
    distractor = np.isin(classes, distractors)
    is_d = distractor[gi]
    if not is_d.any():
        return
    n = len(gb) - 1
    conflicted = conflicted_frames(frame, gi, ri, n, len(g_frame), len(keep_r))
    keep_r[ri[is_d & ~conflicted[frame]]] = False  # one-to-one frames: every strong pair is a match
    solve = np.unique(frame[is_d & conflicted[frame]])  # frames to solve, each on its dense matrix
    block = np.full(n, -1)
    block[solve] = np.arange(len(solve))
    inside = block[frame] >= 0
    f = frame[inside]
    shapes = np.stack([np.diff(gb)[solve], np.diff(rb)[solve]], axis=1)
    local_g, local_r = gi[inside] - gb[f], ri[inside] - rb[f]
    rows, cols, counts = solve_matrices(negated_matrices(shapes, block[f], local_g, local_r, sim[inside]))
    # A match counts where its score is positive: at a listed pair.
    max_r, max_c = (int(v) for v in shapes.max(axis=0)) if len(shapes) else (1, 1)
    matrix = np.repeat(np.arange(len(solve)), counts)
    listed = np.isin((matrix * max_r + rows) * max_c + cols, (block[f] * max_r + local_g) * max_c + local_r)
    rows_at, cols_at = rows + np.repeat(gb[solve], counts), cols + np.repeat(rb[solve], counts)
    keep_r[cols_at[listed & distractor[rows_at]]] = False


def prepare_points(gt_frame: np.ndarray, gt_id: np.ndarray, gt_xy: np.ndarray, result_frame: np.ndarray,
                   result_id: np.ndarray, result_xy: np.ndarray, *, radius: float,
                   num_frames: int | None = None) -> SequenceData:
    """Point sequences (``(n, 2)`` positions, 1-based frames) scored by :func:`point_similarity` at ``radius``."""
    gt = _point_table(gt_frame, gt_id, gt_xy, "gt")
    res = _point_table(result_frame, result_id, result_xy, "result")
    n = _num_frames(gt, res, num_frames)
    check_table(gt, n, "gt")
    check_table(res, n, "result")
    return _per_frame(gt, res, n, lambda a, b: point_similarity(a, b, radius))


def _per_frame(gt: MotTable, res: MotTable, n: int, sim_fn: Callable[..., np.ndarray]) -> SequenceData:
    g_order, g_bounds = _bounds(gt.frame, n)
    r_order, r_bounds = _bounds(res.frame, n)
    gt_ids, tr_ids, sims = [], [], []
    for t in range(n):
        g = g_order[g_bounds[t] : g_bounds[t + 1]]
        r = r_order[r_bounds[t] : r_bounds[t + 1]]
        gt_ids.append(gt.track_id[g])
        tr_ids.append(res.track_id[r])
        sims.append(sim_fn(gt.xywh[g, :2], res.xywh[r, :2]))
    return _finish(gt_ids, tr_ids, sims)


def _whole(values: np.ndarray, name: str) -> np.ndarray:
    """``values`` as integers; ``ValueError`` naming ``name`` and the first value that is not a whole number."""
    raw = np.asarray(values).ravel()
    k = first_fraction(raw)
    if k is not None:
        raise ValueError(f"{name}[{k}]: {raw[k]} is not a whole number")
    return raw.astype(int)


def _point_table(frame: np.ndarray, ids: np.ndarray, xy: np.ndarray, name: str) -> MotTable:
    frame = _whole(frame, f"{name}_frame")
    ids = _whole(ids, f"{name}_id")
    xy = rows_of(xy, 2, f"{name}_xy")
    if not len(frame) == len(ids) == len(xy):
        raise ValueError(f"{name}: frame, id and xy lengths differ ({len(frame)}, {len(ids)}, {len(xy)})")
    if len(frame) and (frame.min() < 1 or not np.isfinite(xy).all()):
        raise ValueError(f"{name}: frames must be >= 1 and positions finite")
    xywh = np.zeros((len(frame), 4))
    xywh[:, :2] = xy
    return MotTableData(frame, ids, xywh, np.ones(len(frame)), np.zeros((len(frame), 0)))


def _num_frames(gt: MotTable, res: MotTable, num_frames: int | None) -> int:
    if num_frames is not None:
        if num_frames < 0:
            raise ValueError(f"num_frames must be >= 0, got {num_frames}")
        return int(num_frames)
    last = [int(t.frame.max()) for t in (gt, res) if len(t)]
    return max(last) if last else 0


def _finish(gt_ids: list[np.ndarray], tr_ids: list[np.ndarray], sims: list[np.ndarray]) -> SequenceData:
    gt_rel, n_gt = _relabel(gt_ids)
    tr_rel, n_tr = _relabel(tr_ids)
    return SequenceData.from_frames(gt_rel, tr_rel, sims, n_gt, n_tr)
