"""The offline closed set's parameters (:func:`lookalike.trackers.offline.closed_set.assign_identities`)."""

from __future__ import annotations

import math
from dataclasses import dataclass

from lookalike.trackers.base import check_positive, param

__all__ = ["ClosedSetConfig"]


@dataclass(frozen=True)
class ClosedSetConfig:
    """Parameters of :func:`assign_identities` (distances in box sizes √(w·h) unless stated)."""

    contact_iou: float | None = param(None, "cut tracks around frames where their box overlaps another's by this "
                                           "IoU (None: never)")
    jump: float = param(3.0, "cut a track at a step longer than this times the 90th-percentile step")
    jump_floor: float = param(0.5, "... and longer than this many box sizes")
    velocity_frames: int = param(5, "rows at a tracklet's end/start that give its velocity")
    pos_sigma: float = param(0.1, "spread of a link's miss at a gap of zero (box sizes)")
    link_cost: float = param(1.0, "cost of every link (rows' worth), so fewer, longer pieces are preferred")
    continue_cost: float = param(-3.0, "cost of re-joining two consecutive pieces of one input track cut at a "
                                       "contact (negative: trust the online pass)")
    max_z: float = param(6.0, "largest miss of a link candidate, in spreads σ")
    candidates: int = param(6, "cheapest successors per end and predecessors per start kept as links")
    max_gap_s: float = param(math.inf, "longest gap (seconds) a link may bridge")
    tracklet_cost: float = param(1.0, "cost of putting a tracklet on an identity (rows' worth); shorter "
                                      "tracklets with costly links are left out as clutter")
    edge_cost: float = param(10.0, "cost (rows' worth) of an identity that starts after the sequence's first "
                                   "frames or ends before its last (a closed set's targets are always there)")
    min_rows: int = param(5, "tracklets with fewer rows are not chained but placed into the chains' gaps")
    fill_gap_s: float = param(math.inf, "longest gap (seconds) inside an identity filled by interpolation "
                                        "(a closed set's targets are always there)")
    smooth_s: float = param(1.0, "longest window (seconds) of the running median of each identity's box "
                                 "centres and sizes (0: none)")
    smooth_move: float = param(0.25, "... and no longer than the frames in which a target typically moves this "
                                     "many box sizes")
    time_limit_s: float = param(60.0, "time limit of the MILP solver (seconds)")

    def __post_init__(self) -> None:
        check_positive(self, "jump", "velocity_frames", "pos_sigma", "max_z", "candidates", "max_gap_s",
                       "time_limit_s")
        check_positive(self, "contact_iou", "jump_floor", "link_cost", "tracklet_cost", "fill_gap_s", "edge_cost",
                       "smooth_s", "smooth_move", allow_zero=True)
