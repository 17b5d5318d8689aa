"""Association as data: an ordered plan of stages (track set, detection set, cost, gate), each solving its own
assignment over the tracks still unmatched and detections still free, in the order it gives them."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import NamedTuple

import numpy as np

from lookalike.association.solver import assign_pairs

CostFn = Callable[[np.ndarray, np.ndarray], np.ndarray]
"""``cost(track_rows, det_indices) -> (len(track_rows), len(det_indices))``; ``inf`` forbids a pair."""

SolveFn = Callable[[np.ndarray], np.ndarray]
"""``solve(cost) -> (k, 2)`` matched ``(row, column)`` positions in the cost matrix."""


class Stage(NamedTuple):
    """One matching pass (immutable).

    Attributes:
        tracks: the eligible track rows, a boolean mask ``(k,)`` or an ordered index array (None: all).
        detections: the eligible detections, a boolean mask ``(n,)`` or an ordered index array (None: all).
        cost: the cost of every eligible (track, detection) pair.
        max_cost: pairs costing more are forbidden (the solver's gate, see :func:`assign`).
        solve: a replacement solver taking the cost matrix (default: :func:`assign` with ``max_cost``).
        name: a label for diagnostics.
        gate: optional boolean ``(k, n)``, True exactly where the cost is allowed (e.g. an IoU threshold); costs are
            then computed only when allowed pairs compete. Ignored with ``solve``."""

    tracks: np.ndarray | None
    detections: np.ndarray | None
    cost: CostFn
    max_cost: float = np.inf
    solve: SolveFn | None = None
    name: str = ""
    gate: np.ndarray | None = None


@dataclass
class Matching:
    """What a plan matched.

    Attributes:
        det_of_track: ``(k,)`` detection index per track row, -1 when unmatched.
        free: ``(n,)`` True for detections no stage took.
        stage_of_track: ``(k,)`` index of the stage that matched each track row, -1 when unmatched."""

    det_of_track: np.ndarray
    free: np.ndarray
    stage_of_track: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=int))

    @classmethod
    def empty(cls, n_tracks: int, n_detections: int) -> Matching:
        """Nothing matched yet."""
        det_of_track, stage_of_track = np.empty(n_tracks, int), np.empty(n_tracks, int)
        free = np.empty(n_detections, bool)
        det_of_track.fill(-1)
        free.fill(True)
        stage_of_track.fill(-1)
        return cls(det_of_track, free, stage_of_track)

    @property
    def pairs(self) -> np.ndarray:
        """``(m, 2)`` matched ``(track row, detection)`` pairs, by track row."""
        rows = np.flatnonzero(self.det_of_track >= 0)
        return np.column_stack([rows, self.det_of_track[rows]]).astype(int)


def _eligible(selector: np.ndarray | None, allowed: np.ndarray) -> np.ndarray:
    if selector is None:
        out: np.ndarray = allowed.nonzero()[0]
        return out
    sel = selector if type(selector) is np.ndarray else np.asarray(selector)
    if sel.dtype == bool:
        return np.logical_and(sel, allowed).nonzero()[0]  # type: ignore[no-any-return]
    idx: np.ndarray = sel.astype(int)
    out = idx[allowed[idx]]
    return out


class _PlanLists:
    """What a plan's gated stages share as Python lists: gates' allowed pairs, boolean selectors, matching columns."""

    def __init__(self) -> None:
        self.pairs: dict[int, list[tuple[int, int]]] = {}
        self.masks: dict[int, list[bool]] = {}
        self.taken: list[int] | None = None
        self.left: list[bool] | None = None

    def run(self, stage: Stage, gate: np.ndarray, matching: Matching, index: int) -> bool:
        """Run a gated stage from its disjoint allowed pairs; False, changing nothing, when they compete."""
        masks = self.masks
        pairs = self.pairs.get(id(gate))
        if pairs is None:
            ti, dj = gate.nonzero()
            pairs = self.pairs[id(gate)] = list(zip(ti.tolist(), dj.tolist()))
        if not pairs:
            return True
        tracks: list[bool] | None = None
        if stage.tracks is not None:
            tracks = masks.get(id(stage.tracks)) or masks.setdefault(id(stage.tracks), stage.tracks.tolist())
            if not any(tracks):
                return True
        dets: list[bool] | None = None
        if stage.detections is not None:
            dets = masks.get(id(stage.detections)) or masks.setdefault(id(stage.detections),
                                                                       stage.detections.tolist())
            if not any(dets):
                return True
        det_of_track, free = matching.det_of_track, matching.free
        taken, left = self.taken, self.left
        if taken is None or left is None:
            taken, left = self.taken, self.left = det_of_track.tolist(), free.tolist()
        found = [(i, j) for i, j in pairs
                 if taken[i] < 0 and left[j] and (tracks is None or tracks[i]) and (dets is None or dets[j])]
        if len(found) > 1 and (len({i for i, _ in found}) < len(found) or len({j for _, j in found}) < len(found)):
            return False
        stage_of_track = matching.stage_of_track
        for i, j in found:
            det_of_track[i] = taken[i] = j
            free[j] = left[j] = False
            stage_of_track[i] = index
        return True


def _label(stage: Stage, index: int) -> str:
    return f"association stage {index}" + (f" ({stage.name})" if stage.name else "")


def _checked(stage: Stage, n_tracks: int, n_detections: int, index: int) -> Stage:
    """``stage`` with list selectors as arrays; ``ValueError`` naming it when a mask, an index array (distinct indices
    in range) or the gate does not fit ``n_tracks`` × ``n_detections``."""
    tracks, detections = stage.tracks, stage.detections
    if tracks is not None and type(tracks) is not np.ndarray:
        tracks = np.asarray(tracks)
    if detections is not None and type(detections) is not np.ndarray:
        detections = np.asarray(detections)
    for what, selector, size in (("tracks", tracks, n_tracks), ("detections", detections, n_detections)):
        if selector is None:
            continue
        if selector.dtype == bool:
            if selector.shape != (size,):
                raise ValueError(f"{_label(stage, index)}: the {what} mask has shape {selector.shape}, expected "
                                 f"({size},)")
        elif len(selector):
            low, high = int(selector.min()), int(selector.max())
            if low < 0 or high >= size or len(np.unique(selector)) < len(selector):
                bad = low if low < 0 else high if high >= size else "one twice"
                raise ValueError(f"{_label(stage, index)}: the {what} indices must be distinct, from 0 to {size - 1}; "
                                 f"got {bad}")
    if stage.gate is not None and stage.gate.shape != (n_tracks, n_detections):
        raise ValueError(f"{_label(stage, index)}: the gate has shape {stage.gate.shape}, expected "
                         f"({n_tracks}, {n_detections}) (tracks × detections)")
    if tracks is stage.tracks and detections is stage.detections:
        return stage
    return stage._replace(tracks=tracks, detections=detections)


def run_stage(stage: Stage, matching: Matching, index: int = 0, _lists: _PlanLists | None = None) -> Matching:
    """Run one stage on what ``matching`` left over (updated in place and returned). A mask or gate that does not
    fit the tracks and detections, or a cost of another shape than eligible tracks × detections, raises
    ``ValueError`` naming the stage."""
    if _lists is None:  # (run_plan checked its stages)
        stage = _checked(stage, len(matching.det_of_track), len(matching.free), index)
    gate = stage.gate if stage.solve is None else None
    if gate is not None and (stage.tracks is None or stage.tracks.dtype == bool) and (
            stage.detections is None or stage.detections.dtype == bool):
        lists = _PlanLists() if _lists is None else _lists
        if lists.run(stage, gate, matching, index):
            return matching
        gate = None  # the allowed pairs compete: the costs decide
    rows = _eligible(stage.tracks, matching.det_of_track < 0)
    if not len(rows):
        return matching
    cols = _eligible(stage.detections, matching.free)
    if not len(cols):
        return matching
    if gate is not None:
        i, j = gate[rows[:, None], cols].nonzero()  # row-major, as the solver lists them
        if not len(i):
            return matching
        if len(i) == 1 or (len(set(i.tolist())) == len(i) and len(set(j.tolist())) == len(j)):
            r, c = rows[i], cols[j]  # disjoint allowed pairs: the matches of every optimum
            matching.det_of_track[r] = c
            matching.free[c] = False
            matching.stage_of_track[r] = index
            return matching
    cost = stage.cost(rows, cols)
    if cost.shape != (len(rows), len(cols)):
        raise ValueError(f"{_label(stage, index)}: its cost has shape {cost.shape}, expected ({len(rows)}, "
                         f"{len(cols)}) (eligible tracks × detections)")
    found = stage.solve(cost) if stage.solve is not None else assign_pairs(cost, stage.max_cost)
    if len(found):
        r, c = rows[found[:, 0]], cols[found[:, 1]]
        matching.det_of_track[r] = c
        matching.free[c] = False
        matching.stage_of_track[r] = index
        if _lists is not None:
            _lists.taken = _lists.left = None
    return matching


def run_plan(stages: list[Stage], n_tracks: int, n_detections: int,
             start: Matching | None = None) -> Matching:
    """Run ``stages`` in order on the tracks and detections (or on what ``start`` left over); ``ValueError`` naming
    the stage for a mask, gate or cost that does not fit (:func:`run_stage`)."""
    matching = start if start is not None else Matching.empty(n_tracks, n_detections)
    k, n = len(matching.det_of_track), len(matching.free)
    checked = [_checked(stage, k, n, i) for i, stage in enumerate(stages)]  # (kept: the lists key on them)
    lists = _PlanLists()  # what the gated stages share, found once per plan
    for i, stage in enumerate(checked):
        run_stage(stage, matching, i, lists)
    return matching


def cascade(track_age: np.ndarray, max_age: int, tracks: np.ndarray, detections: np.ndarray,
            cost: CostFn, max_cost: float = np.inf) -> list[Stage]:
    """Deep SORT's matching cascade: one stage per age 1 .. ``max_age`` of ``tracks`` (a mask), newest first."""
    age = np.asarray(track_age)
    levels = np.unique(age[tracks & (age >= 1) & (age <= max_age)])
    return [Stage(tracks & (age == level), detections, cost, max_cost, name=f"cascade level {level}")
            for level in levels]
