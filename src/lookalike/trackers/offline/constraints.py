"""Constraints on the offline closed set from a proofreader (:class:`ChainConstraints`), and how they enter
:func:`lookalike.trackers.offline.closed_set.solve_chains`' MILP as marks: per mark, a binary per tracklet (marked),
equal across every used link, with at most one marked chain head, so exactly the chain holding the mark's tracklets
carries it. Frames 1-based; rows named ``(frame, input id)``."""

from __future__ import annotations

from collections.abc import Collection, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from lookalike.trackers.offline.closed_set_config import ClosedSetConfig
from lookalike.trackers.offline.tracklets import Tracklet

__all__ = ["ChainConstraints", "Row", "chain_ids", "constraint_marks", "cut_tracklets", "tracklet_of", "with_marks"]

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


def with_marks(A: Any, lo: np.ndarray, hi: np.ndarray, c: np.ndarray, lower: np.ndarray, upper: np.ndarray,
                n: int, links: tuple[np.ndarray, np.ndarray],
                marks: Sequence[tuple[Collection[int], Collection[int]]]) -> tuple[Any, ...]:
    """The chain problem of :func:`~lookalike.trackers.offline.closed_set.solve_chains` (constraint matrix ``A``,
    bounds ``lo``/``hi``, costs ``c``, variable bounds ``lower``/``upper``; ``n`` tracklets, ``links`` ``(src, dst)``)
    with, per mark, variables ``z`` (tracklet marked) and ``h`` (chain head marked) after the ``4n + m`` of the
    chains, and their constraints."""
    from scipy import sparse

    src, dst = links
    m = len(src)
    base = A.shape[1]
    blocks, los, his = [], [], []
    for k in range(len(marks)):
        z0 = base + 2 * n * k  # z [z0, z0+n), h [z0+n, z0+2n)
        e = np.arange(m)
        # a used link joins two equally marked tracklets: z_s - z_d + y ≤ 1 and z_d - z_s + y ≤ 1
        r = np.r_[e, e, e, m + e, m + e, m + e]
        col = np.r_[z0 + src, z0 + dst, n + e, z0 + dst, z0 + src, n + e]
        val = np.r_[np.ones(m), -np.ones(m), np.ones(m), np.ones(m), -np.ones(m), np.ones(m)]
        i = np.arange(n)
        # z_i - x_i ≤ 0; a_i + z_i - h_i ≤ 1; Σ h ≤ 1
        r = np.r_[r, 2 * m + i, 2 * m + i, 2 * m + n + i, 2 * m + n + i, 2 * m + n + i, np.full(n, 2 * m + 2 * n)]
        col = np.r_[col, z0 + i, i, n + m + i, z0 + i, z0 + n + i, z0 + n + i]
        val = np.r_[val, np.ones(n), -np.ones(n), np.ones(n), np.ones(n), -np.ones(n), np.ones(n)]
        width = base + 2 * n * len(marks)
        blocks.append(sparse.csr_matrix((val, (r, col)), shape=(2 * m + 2 * n + 1, width)))
        los.append(np.full(2 * m + 2 * n + 1, -np.inf))
        his.append(np.r_[np.ones(2 * m), np.zeros(n), np.ones(n), 1.0])
    extra = 2 * n * len(marks)
    A = sparse.vstack([sparse.hstack([A, sparse.csr_matrix((A.shape[0], extra))]), *blocks]).tocsr()
    lower = np.r_[lower, np.zeros(extra)]
    upper = np.r_[upper, np.ones(extra)]
    for k, (on, off) in enumerate(marks):
        z0 = base + 2 * n * k
        lower[[z0 + t for t in on]] = 1.0
        upper[[z0 + t for t in off]] = 0.0
    return A, np.concatenate([lo, *los]), np.concatenate([hi, *his]), np.r_[c, np.zeros(extra)], lower, upper


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


def tracklet_of(tracklets: list[Tracklet], row: Row) -> int:
    """Index of the tracklet holding the input row ``(frame, input id)``; ValueError when none does."""
    frame, source = int(row[0]), int(row[1])
    for i, t in enumerate(tracklets):
        if t.source_id == source and t.first <= frame <= t.last and np.any(t.rows[:, 0] == frame):
            return i
    raise ValueError(f"constraint: no input row of id {source} at frame {frame}")


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
