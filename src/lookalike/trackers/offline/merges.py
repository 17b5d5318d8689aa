"""Animals inside merged blobs, for the offline closed set: an identity whose first or last row leads into a merged blob
stays in it (:func:`hold_in_merges`); the identities interpolated through (or held in) a contact are moved onto the
merged blob (:func:`place_in_merges`), on its parts where the detector split it, by one least-cost path over all the
frames (Viterbi smoothing), so each frame's placement weighs the frames before and after it."""

from __future__ import annotations

import heapq
import math

import numpy as np

from lookalike.trackers.offline.appearance import SHAPE_COLUMN
from lookalike.trackers.offline.tracklets import row_centres

__all__ = ["hold_in_merges", "place_in_merges"]

MERGE_REACH = 0.25  # an interpolated centre this many blob sizes sqrt(w*h) outside a merged blob's box is not in it
MAX_STATES = 120  # placements kept per frame (the least own cost first)
MAX_LEAVES = 20_000  # placements listed one by one up to about this many; beyond, the MAX_STATES cheapest (Murty)


def place_in_merges(rows: np.ndarray, measured: np.ndarray, merged: np.ndarray, shapes: np.ndarray | None = None,
                    parts: np.ndarray | None = None) -> np.ndarray:
    """Result ``rows`` ``(k, >= 6)`` (1-based frame, id, ``x, y, w, h`` px) with the identities that share a merged
    blob moved onto it. ``measured``: mask of the rows that hold a detection (the others were interpolated across a
    gap); ``merged``: rows of the merged blobs (frame, -, box, ..., column 9 indexing ``shapes`` and ``parts``).

    In each merged blob's frame the interpolated rows whose centres lie within its box (:data:`MERGE_REACH`) are its
    animals; the two farthest apart keep their order along the line between them and move to the box's ends on that
    line, each its own typical size (median measured ``w, h``) inside the box; any others stay interpolated. With the
    blobs' ``parts`` (:func:`~lookalike.vision.blob_shape.blob_part_vectors`) and ``shapes``, the identities then
    take the parts' centroids instead (:func:`_on_parts`)."""
    out = np.array(rows, dtype=float, copy=True)
    ids = out[:, 1].astype(int)
    size = {i: np.median(out[measured & (ids == i), 4:6], axis=0) if np.any(measured & (ids == i)) else None
            for i in np.unique(ids).tolist()}
    loose = np.flatnonzero(~measured)
    frames = out[loose, 0].astype(int)
    for f, box in zip(merged[:, 0].astype(int), merged[:, 2:6]):
        x0, y0, w, h = box
        centre = np.array([x0 + w / 2, y0 + h / 2])
        ks = loose[frames == f]
        c = row_centres(out[ks])
        inside = _within(c, box, MERGE_REACH)
        ks, c = ks[inside], c[inside]
        if len(ks) < 2:
            continue
        gaps = np.linalg.norm(c[:, None] - c[None], axis=2)
        a, b = np.unravel_index(np.argmax(gaps), gaps.shape)
        if gaps[a, b] < 1.0:
            continue
        d = (c[b] - c[a]) / gaps[a, b]
        extent = abs(d[0]) * w + abs(d[1]) * h  # the box's width along d
        for k, side in ((ks[a], -1.0), (ks[b], 1.0)):
            own = size[int(out[k, 1])]
            own = out[k, 4:6] if own is None else own
            out[k, 2:4] = centre + side * d * max(extent - abs(d[0]) * own[0] - abs(d[1]) * own[1], 0.0) / 2 \
                - out[k, 4:6] / 2
    if parts is not None and shapes is not None and len(merged):
        _on_parts(out, np.asarray(rows, dtype=float), loose, merged, np.exp(shapes[:, 0]), parts)
    return out


def hold_in_merges(rows: np.ndarray, pieces: list[np.ndarray]) -> np.ndarray:
    """Result ``rows`` ``(k, >= 6)`` (1-based frame, id, ``x, y, w, h`` px) with each identity continued through the
    merged piece its first or last row leads into: where a row of a merged piece (``pieces``: rows of merged blobs,
    one per frame, in order) in the frame after an identity's last row holds its centre (the blob's box widened by
    :data:`MERGE_REACH` blob sizes), the identity follows the piece to its end, one row a frame at the blob's centre
    with its own last size; the same backwards from its first row. Returns the rows, new ones included, by frame
    and id."""
    found: dict[int, list[tuple[int, int]]] = {}  # frame -> (piece, row)
    for p, piece in enumerate(pieces):
        for k, f in enumerate(piece[:, 0].astype(int).tolist()):
            found.setdefault(f, []).append((p, k))
    out = [rows]
    ids = rows[:, 1].astype(int)
    for i in np.unique(ids).tolist():
        mine = rows[ids == i]
        mine = mine[np.argsort(mine[:, 0], kind="stable")]
        for end, step in ((mine[-1], 1), (mine[0], -1)):
            c = row_centres(end[None])
            for p, k in found.get(int(end[0]) + step, []):
                if _within(c, pieces[p][k, 2:6], MERGE_REACH)[0]:
                    follow = pieces[p][k:] if step > 0 else pieces[p][:k + 1]
                    new = np.repeat(end[None], len(follow), axis=0)
                    new[:, 0] = follow[:, 0]
                    new[:, 2:4] = row_centres(follow) - end[4:6] / 2
                    out.append(new)
                    break
    held = np.vstack(out)
    return held[np.lexsort((held[:, 1], held[:, 0]))]


def _within(centres: np.ndarray, box: np.ndarray, reach: float) -> np.ndarray:
    """Mask of the ``centres`` ``(k, 2)`` (px) inside ``box`` (left, top, w, h; px) widened on every side by ``reach``
    blob sizes ``sqrt(w*h)``."""
    x0, y0, w, h = box
    out: np.ndarray = np.all(np.abs(np.reshape(centres, (-1, 2)) - [x0 + w / 2, y0 + h / 2])
                             <= np.array([w, h]) / 2 + reach * math.sqrt(w * h), axis=1)
    return out


def _placements(ok: np.ndarray, cost: np.ndarray) -> list[list[tuple[int, int]]]:
    """The one-to-one placements of identities (rows of ``ok``) on parts (columns) with as many pairs as any allowed
    placement has; ``ok[i, j]``: identity ``i`` may take part ``j`` at ``cost[i, j]``. Every one where they are few
    (:data:`MAX_LEAVES`), else the :data:`MAX_STATES` of least total cost (:func:`_cheapest_placements`)."""
    if np.prod(1.0 + ok.sum(axis=1)) > MAX_LEAVES:
        return _cheapest_placements(np.where(ok, cost, np.inf), MAX_STATES)
    found: list[list[tuple[int, int]]] = []

    def extend(i: int, used: frozenset[int], pairs: list[tuple[int, int]]) -> None:
        if i == len(ok):
            found.append(pairs)
            return
        extend(i + 1, used, pairs)
        for j in np.flatnonzero(ok[i]).tolist():
            if j not in used:
                extend(i + 1, used | {j}, [*pairs, (i, j)])

    extend(0, frozenset(), [])
    most = max(len(p) for p in found)
    return [p for p in found if len(p) == most]


def _cheapest_placements(cost: np.ndarray, k: int) -> list[list[tuple[int, int]]]:
    """Up to ``k`` one-to-one placements of rows on columns of ``cost`` (inf: not allowed) with as many allowed pairs
    as any has, least total cost first: Murty's ranking of assignments, each subproblem solved by scipy."""
    from scipy.optimize import linear_sum_assignment

    allowed = np.isfinite(cost)
    unplaced = float(cost[allowed].sum()) + 1.0  # a pair on a part not allowed: worse than any allowed placement
    barred = unplaced * (min(cost.shape) + 1)  # a pair a subproblem excludes: never in a solution below this

    def solve(forced: tuple[tuple[int, int], ...], banned: tuple[tuple[int, int], ...]
              ) -> tuple[float, list[tuple[int, int]]] | None:
        c = np.where(allowed, cost, unplaced)
        for i, j in banned:
            c[i, j] = barred
        for i, j in forced:
            keep = c[i, j]
            c[i, :], c[:, j] = barred, barred
            c[i, j] = keep
        rows, cols = linear_sum_assignment(c)
        total = float(c[rows, cols].sum())
        return None if total >= barred else (total, list(zip(rows.tolist(), cols.tolist())))

    first = solve((), ())
    if first is None:
        return [[]]
    most = sum(allowed[i, j] for i, j in first[1])
    Pairs = tuple[tuple[int, int], ...]
    queue: list[tuple[float, int, Pairs, Pairs, list[tuple[int, int]]]] = [(first[0], 0, (), (), first[1])]
    out: list[list[tuple[int, int]]] = []
    seen: set[frozenset[tuple[int, int]]] = set()
    count = 1
    while queue and len(out) < k:
        _, _, forced, banned, pairs = heapq.heappop(queue)
        placed = [(i, j) for i, j in pairs if allowed[i, j]]
        if len(placed) == most and frozenset(placed) not in seen:
            seen.add(frozenset(placed))
            out.append(placed)
        free = [p for p in pairs if p not in forced]
        for t, pair in enumerate(free):
            branch = solve((*forced, *free[:t]), (*banned, pair))
            if branch is not None:
                heapq.heappush(queue, (branch[0], count, (*forced, *free[:t]), (*banned, pair), branch[1]))
                count += 1
    return out


def _transition(prev: np.ndarray, now: np.ndarray, exit_to: np.ndarray, enter_from: np.ndarray) -> np.ndarray:
    """``(S1, S2)`` costs (px) between placements ``prev`` ``(S1, U, 2)`` and ``now`` ``(S2, U, 2)`` of the same ``U``
    identities in consecutive frames (NaN: not placed): an identity placed in both moves between its parts; placed
    before only, from its part to its centre ``exit_to`` ``(U, 2)`` in the later frame; placed after only, from its
    centre ``enter_from`` in the earlier frame to its part (NaN centres: nothing)."""
    placed_prev, placed_now = ~np.isnan(prev[..., 0]), ~np.isnan(now[..., 0])
    both = np.linalg.norm(prev[:, None] - now[None], axis=3)
    leave = np.nan_to_num(np.linalg.norm(prev - exit_to, axis=2))
    enter = np.nan_to_num(np.linalg.norm(enter_from - now, axis=2))
    cost = np.where(placed_prev[:, None] & placed_now[None], both,
                    np.where(placed_prev[:, None], leave[:, None], 0.0) + np.where(placed_now[None], enter[None], 0.0))
    out: np.ndarray = np.nan_to_num(cost).sum(axis=2)
    return out


def _on_parts(out: np.ndarray, before: np.ndarray, loose: np.ndarray, merged: np.ndarray, areas: np.ndarray,
             parts: np.ndarray) -> None:
    """Move the interpolated rows ``loose`` of ``out`` onto the parts of the merged blobs, all frames at once.

    A merged blob holds as many animals as the interpolated identities inside its box (widened by
    :data:`MERGE_REACH` blob sizes) when they are 2 or 3, else its area (px², ``areas`` by column 9) over the median
    blob's, rounded, 2 or 3; its parts are the centroids of that split (no parts: left as they are); an identity more
    than one blob size ``sqrt(w*h)`` outside a blob's box cannot take its parts. The placement of every frame is one
    path of least total cost: in each frame the distances from the placed identities' interpolated centres (in
    ``before``) to their parts, and between consecutive frames the distance each identity moves (from or to its centre
    in ``before`` where it is placed in one of the two frames only)."""
    single = float(np.median(areas))
    frames = before[loose, 0].astype(int)
    centre = {(int(f), int(i)): (x + w / 2, y + h / 2) for f, i, x, y, w, h in before[:, :6]}
    merged = merged[np.argsort(merged[:, 0], kind="stable")]
    steps = []  # per frame with parts: (frame, rows ks, identities, parts at, placements (S, len(ks), 2), own cost)
    for f in np.unique(merged[:, 0]).astype(int):
        ks = loose[frames == f]
        if not len(ks):
            continue
        c = row_centres(before[ks])
        slots, allowed = [], []
        for row in merged[merged[:, 0] == f]:
            inside = int(np.count_nonzero(_within(c, row[2:6], MERGE_REACH)))
            count = inside if 2 <= inside <= 3 else int(np.clip(round(areas[int(row[SHAPE_COLUMN])] / single), 2, 3))
            part = parts[int(row[SHAPE_COLUMN])]
            part = part[:4] if count == 2 else part[4:]
            if np.isnan(part).any():
                continue
            slots.extend(part.reshape(count, 2))
            allowed.extend([_within(c, row[2:6], 1.0)] * count)
        if not slots:
            continue
        at = np.array(slots)
        options = _placements(np.array(allowed).T, np.linalg.norm(c[:, None] - at[None], axis=2))
        at_of = np.full((len(options), len(ks), 2), np.nan)
        for s, pairs in enumerate(options):
            for i, j in pairs:
                at_of[s, i] = at[j]
        own = np.nan_to_num(np.linalg.norm(at_of - c, axis=2)).sum(axis=1)
        keep = np.argsort(own, kind="stable")[:MAX_STATES]
        steps.append((f, ks, before[ks, 1].astype(int), at_of[keep], own[keep]))
    if not steps:
        return
    f, _, ids, at_of, own = steps[0]
    total = own + _ends(at_of, ids, centre, f - 1)  # least cost of a path ending in each placement of this frame
    back = []  # per later frame: each placement's best predecessor
    for (pf, _, pids, p_at, _), (f, _, ids, at_of, own) in zip(steps, steps[1:]):
        if pf == f - 1:
            union = np.union1d(pids, ids)
            exit_to = np.array([centre.get((f, int(i)), (np.nan, np.nan)) for i in union])
            enter_from = np.array([centre.get((pf, int(i)), (np.nan, np.nan)) for i in union])
            cost = total[:, None] + _transition(_on_union(p_at, pids, union), _on_union(at_of, ids, union), exit_to,
                                                enter_from)
            back.append(np.argmin(cost, axis=0))
            total = cost.min(axis=0) + own
        else:  # a gap: the earlier frame leaves towards its next frame, this one enters from its previous
            leave = total + _ends(p_at, pids, centre, pf + 1)
            best = int(np.argmin(leave))
            back.append(np.full(len(own), best))
            total = leave[best] + own + _ends(at_of, ids, centre, f - 1)
    last = steps[-1]
    total = total + _ends(last[3], last[2], centre, last[0] + 1)
    s = int(np.argmin(total))
    for t in range(len(steps) - 1, -1, -1):
        _, ks, _, at_of, _ = steps[t]
        placed = ~np.isnan(at_of[s, :, 0])
        out[ks[placed], 2:4] = at_of[s, placed] - out[ks[placed], 4:6] / 2
        if t:
            s = int(back[t - 1][s])


def _on_union(at_of: np.ndarray, ids: np.ndarray, union: np.ndarray) -> np.ndarray:
    """Placements ``(S, len(ids), 2)`` spread onto the identities ``union`` (NaN: not in ``ids``)."""
    out = np.full((len(at_of), len(union), 2), np.nan)
    out[:, np.searchsorted(union, ids)] = at_of
    return out


def _ends(at_of: np.ndarray, ids: np.ndarray, centre: dict[tuple[int, int], tuple[float, float]],
          frame: int) -> np.ndarray:
    """``(S,)`` distances (px) from each placement's parts to the identities' centres in ``frame`` (none: 0)."""
    there = np.array([centre.get((frame, int(i)), (np.nan, np.nan)) for i in ids]).reshape(-1, 2)
    out: np.ndarray = np.nan_to_num(np.linalg.norm(at_of - there, axis=2)).sum(axis=1)
    return out
