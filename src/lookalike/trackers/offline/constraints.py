"""Constraints on the offline closed set from a proofreader (:class:`ChainConstraints`), and how they enter
:func:`lookalike.trackers.offline.closed_set.solve_chains`' MILP as marks: per mark, one unit of flow along the chain
that holds the mark's tracklets, over only the tracklets that can share a chain with them. Frames 1-based; rows named
``(frame, input id)``."""

from __future__ import annotations

from collections.abc import Collection, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from lookalike.trackers.offline.closed_set_config import ClosedSetConfig
from lookalike.trackers.offline.tracklets import Tracklet

__all__ = ["ChainConstraints", "Row", "chain_ids", "constraint_marks", "cut_tracklets", "holds", "tracklet_of",
           "with_marks"]

Row = tuple[int, int]  # (1-based frame, input id): one input row


@dataclass(frozen=True)
class ChainConstraints:
    """Constraints on :func:`assign_identities`, each naming input rows by ``(frame, input id)`` (1-based frame, the
    id the row has in the input).

    ``cut``: the row's input track is cut just before it (so a constraint can hold from that frame on);
    ``identity``: ``(row, j)``, the tracklet holding the row is identity ``j`` (1..N);
    ``apart``: pairs of rows whose tracklets are never on one identity;
    ``clutter``: rows whose tracklets are on no identity."""

    cut: tuple[Row, ...] = ()
    identity: tuple[tuple[Row, int], ...] = ()
    apart: tuple[tuple[Row, Row], ...] = ()
    clutter: tuple[Row, ...] = ()

    def rows(self) -> list[Row]:
        """Every row a constraint names."""
        return [r for r, _ in self.identity] + [r for pair in self.apart for r in pair] + list(self.clutter)


def _reach(n: int, src: np.ndarray, dst: np.ndarray, start: int) -> np.ndarray:
    """Whether each of ``n`` tracklets can be reached from ``start`` along the links ``src -> dst`` (itself too)."""
    from scipy import sparse
    from scipy.sparse.csgraph import breadth_first_order

    graph = sparse.csr_matrix((np.ones(len(src)), (src, dst)), shape=(n, n))
    seen = np.zeros(n, bool)
    seen[breadth_first_order(graph, start, return_predecessors=False)] = True
    return seen


def with_marks(A: Any, lo: np.ndarray, hi: np.ndarray, c: np.ndarray, lower: np.ndarray, upper: np.ndarray,
               n: int, links: tuple[np.ndarray, np.ndarray],
               marks: Sequence[tuple[Collection[int], Collection[int]]]) -> tuple[Any, ...]:
    """The chain problem of :func:`~lookalike.trackers.offline.closed_set.solve_chains` (constraint matrix ``A``,
    bounds ``lo``/``hi``, costs ``c``, variable bounds ``lower``/``upper``; ``n`` tracklets, ``links`` ``(src, dst)``,
    forward in time) with, per mark, one unit of flow along the chain that carries it, after the ``4n + m`` variables
    of the chains: over the tracklets that can share a chain with all of its ``on`` and are not ``off`` (linked to or
    from each), ``h``/``t`` (the flow starts/ends there: at most ``a``/``b``) and ``f`` per link between two of them
    (at most ``y``); conserved at each, ``Σ h ≤ 1``, and one unit through each ``on``."""
    from scipy import sparse

    src, dst = links
    m = len(src)
    blocks: list[Any] = []
    los, his, lows, ups = [lo], [hi], [lower], [upper]
    width = A.shape[1]
    for on, off in marks:
        if set(on) & set(off):
            raise ValueError("constraint: a tracklet both carries a mark and does not")
        keep = np.ones(n, bool)
        for t in on:
            keep &= _reach(n, src, dst, t) | _reach(n, dst, src, t)
        keep[list(off)] = False
        keep[list(on)] = True  # two of them on no common chain: no flow goes through both below
        nodes = np.flatnonzero(keep)
        k = len(nodes)
        edges = np.flatnonzero(keep[src] & keep[dst])
        e = len(edges)
        at = np.full(n, -1)
        at[nodes] = np.arange(k)
        f0, h0, t0 = width, width + e, width + e + k  # f [f0, f0+e), h [h0, h0+k), t [t0, t0+k)
        s, d = at[src[edges]], at[dst[edges]]
        ie, ik = np.arange(e), np.arange(k)
        # rows: conservation h + Σ f_in - t - Σ f_out = 0 (k); f - y ≤ 0 (e); h - a ≤ 0, t - b ≤ 0 (2k); Σ h ≤ 1;
        # through each `on`: h + Σ f_in = 1
        on_at = at[list(on)]
        io = np.arange(len(on_at))
        r0 = k + e + 2 * k + 1
        into = np.isin(d, on_at)
        pos = {int(v): q for q, v in enumerate(on_at)}
        r = np.r_[ik, d, ik, s, k + ie, k + ie, k + e + ik, k + e + ik, k + e + k + ik, k + e + k + ik,
                  np.full(k, k + e + 2 * k), r0 + io, r0 + np.array([pos[int(v)] for v in d[into]], int)]
        col = np.r_[h0 + ik, f0 + ie, t0 + ik, f0 + ie, f0 + ie, n + edges, h0 + ik, n + m + nodes, t0 + ik,
                    2 * n + m + nodes, h0 + ik, h0 + on_at, f0 + ie[into]]
        val = np.r_[np.ones(k), np.ones(e), -np.ones(k), -np.ones(e), np.ones(e), -np.ones(e), np.ones(k), -np.ones(k),
                    np.ones(k), -np.ones(k), np.ones(k), np.ones(len(on_at)), np.ones(int(into.sum()))]
        rows = r0 + len(on_at)
        blocks.append((r, col, val, rows))
        los.append(np.r_[np.zeros(k), np.full(e + 2 * k + 1, -np.inf), np.ones(len(on_at))])
        his.append(np.r_[np.zeros(k), np.zeros(e + 2 * k), 1.0, np.ones(len(on_at))])
        lows.append(np.zeros(e + 2 * k))
        ups.append(np.ones(e + 2 * k))
        width += e + 2 * k
    extra = width - A.shape[1]
    mats = [sparse.csr_matrix((val, (r, col)), shape=(rows, width)) for r, col, val, rows in blocks]
    A = sparse.vstack([sparse.hstack([A, sparse.csr_matrix((A.shape[0], extra))]), *mats]).tocsr()
    return A, np.concatenate(los), np.concatenate(his), np.r_[c, np.zeros(extra)], np.concatenate(lows), \
        np.concatenate(ups)


def cut_tracklets(pieces: list[Tracklet], cuts: Sequence[Row]) -> list[Tracklet]:
    """``pieces`` with each cut just before the rows named by ``cuts`` (1-based frame, input id)."""
    at: dict[int, set[int]] = {}
    for frame, source in cuts:
        at.setdefault(int(source), set()).add(int(frame))
    out: list[Tracklet] = []
    for t in pieces:
        frames = sorted(f for f in at.get(t.source_id, ()) if t.first < f <= t.last)
        if not frames:
            out.append(t)
            continue
        bounds = np.searchsorted(t.rows[:, 0], frames)
        out += [Tracklet(r, t.source_id, t.contact) for r in np.split(t.rows, bounds) if len(r)]
    out.sort(key=lambda t: (t.first, t.last))
    return out


def _holder(tracklets: list[Tracklet], row: Row) -> int | None:
    frame, source = int(row[0]), int(row[1])
    for i, t in enumerate(tracklets):
        if t.source_id == source and t.first <= frame <= t.last and np.any(t.rows[:, 0] == frame):
            return i
    return None


def holds(tracklets: list[Tracklet], row: Row) -> bool:
    """Whether one of ``tracklets`` holds the input row ``(frame, input id)``."""
    return _holder(tracklets, row) is not None


def tracklet_of(tracklets: list[Tracklet], row: Row) -> int:
    """Index of the tracklet holding the input row ``(frame, input id)``; ValueError when none does."""
    i = _holder(tracklets, row)
    if i is None:
        raise ValueError(f"constraint: no input row of id {int(row[1])} at frame {int(row[0])}")
    return i


def constraint_marks(tracklets: list[Tracklet], cons: ChainConstraints, n_targets: int,
           links: tuple[np.ndarray, np.ndarray, np.ndarray], cfg: ClosedSetConfig) -> tuple[Any, ...]:
    """The fixed identity per tracklet, the marks and exclusions of
    :func:`~lookalike.trackers.offline.closed_set.solve_chains` and the links with a direct
    link added between consecutive tracklets fixed to one identity (at the dearest candidate's cost), so the
    constraints can always be met by some chain."""
    fixed: dict[int, int] = {}
    for row, j in cons.identity:
        if not 1 <= int(j) <= n_targets:
            raise ValueError(f"constraint: identity {j} is not in 1..{n_targets}")
        t = tracklet_of(tracklets, row)
        if fixed.get(t, j) != j:
            raise ValueError(f"constraint: the tracklet of row {row} is fixed to identities {fixed[t]} and {j}")
        fixed[t] = int(j)
    excluded = sorted({tracklet_of(tracklets, r) for r in cons.clutter})
    if set(excluded) & set(fixed):
        raise ValueError("constraint: a tracklet is both on an identity and clutter")
    src, dst, cost = links
    known = set(zip(src.tolist(), dst.tolist()))
    dear = float(cost.max()) if len(cost) else cfg.link_cost
    add: list[tuple[int, int]] = []
    marks: list[tuple[Collection[int], Collection[int]]] = []
    for j in sorted(set(fixed.values())):
        on = sorted((t for t in fixed if fixed[t] == j), key=lambda t: tracklets[t].first)
        for p, q in zip(on[:-1], on[1:]):
            if tracklets[p].last >= tracklets[q].first:
                raise ValueError(f"constraint: identity {j} is fixed to two tracklets that overlap in frames "
                                 f"{tracklets[q].first}-{min(tracklets[p].last, tracklets[q].last)}")
            if (p, q) not in known:
                add.append((p, q))
        marks.append((on, [t for t in fixed if fixed[t] != j]))
    for a_row, b_row in cons.apart:
        a, b = tracklet_of(tracklets, a_row), tracklet_of(tracklets, b_row)
        if a == b or (a in fixed and fixed.get(b) == fixed[a]):
            raise ValueError(f"constraint: rows {a_row} and {b_row} cannot be apart (same tracklet or identity)")
        marks.append(([a], [b]))
    if add:
        p, q = np.array(add).T
        links = (np.r_[src, p], np.r_[dst, q], np.r_[cost, np.full(len(add), dear)])
    return fixed, marks, excluded, links


def chain_ids(chains: list[list[int]], fixed: dict[int, int], n_targets: int) -> list[int]:
    """Id of each chain (in order): the identity fixed to one of its tracklets, else the free ids in order."""
    ids = [next((fixed[t] for t in ch if t in fixed), 0) for ch in chains]
    free = iter(sorted(set(range(1, max(n_targets, len(chains)) + 1)) - set(ids)))
    return [i or next(free) for i in ids]
