"""Diver SORT's configuration and its identity-merge record; where the defaults come from is
docs/trackers/diversort.md."""

from __future__ import annotations

from dataclasses import dataclass

from lookalike.trackers.base import COUNT, COUNT0, NON_NEGATIVE, POSITIVE, Range, check_params, param


@dataclass(frozen=True)
class Merge:
    """An identity recovery: from ``frame_index`` on, track ``source_id`` is reported as ``target_id``."""

    frame_index: int
    source_id: int
    target_id: int


@dataclass(frozen=True)
class DiverSortConfig:
    """Diver SORT's parameters (pixels, frames, cosine distances); validated on construction."""

    iou_shortcut: float = param(0.75, "IoU with last frame's detection that joins its track directly",
                                range=Range(0, 1, low_open=True))
    appearance_threshold: float = param(0.10, "largest cosine cost of a match (paper 1e-4 for its features)",
                                        range=Range(0, 2, low_open=True))
    long_term_threshold: float = param(0.30, "threshold for tracks unseen > long_term_after (paper 5e-4)",
                                       range=Range(0, 2, low_open=True))
    location_gate: float = param(9.21, "largest squared Mahalanobis distance of the centre (paper 25)", range=POSITIVE)
    location_weight: float = param(0.1, "weight of d²/location_gate added to tied costs", range=NON_NEGATIVE)
    tie_margin: float = param(0.02, "tracks this close to a detection's best cost count as tied", range=NON_NEGATIVE)
    long_term_after: int = param(5, "frames unseen after which only appearance is used", range=COUNT0)
    recent_first: bool = param(False, "match recently seen tracks before long-unseen ones (ours)")
    n_init: int = param(3, "consecutive matches that make a track an identity", range=COUNT)
    recovery_window: int = param(15, "a track alive this many frames or fewer may be merged", range=COUNT)
    recovery_fraction: float = param(0.25, "share of gallery pairs under the threshold that merges",
                                     range=Range(0, 1, high_open=True))
    recovery_threshold: float = param(0.30, "cosine distance counted as similar for recovery", range=(0, 2))
    gallery_size: int = param(100, "features kept per track", range=COUNT)
    max_age: int | None = param(None, "frames a confirmed track survives unseen (None: forever)", range=COUNT)
    max_lost: int | None = param(200, "unseen confirmed tracks kept for re-identification; beyond it the longest "
                                 "unseen is forgotten (None: no cap, memory grows)", range=COUNT)
    position_std_frac: float = param(0.15, "centre measurement noise as a fraction of box height", range=POSITIVE)
    accel_std_frac: float = param(1 / 20, "centre acceleration noise per frame, fraction of box height", range=POSITIVE)
    frame_interval_s: float | None = param(None, "seconds per frame (None: the smallest step seen)", range=POSITIVE)

    def __post_init__(self) -> None:
        check_params(self)
