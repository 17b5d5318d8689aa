"""Diver SORT's configuration and its identity-merge record; where the defaults come from is
docs/trackers/diversort.md."""

from __future__ import annotations

from dataclasses import dataclass

from lookalike.trackers.base import check_positive, param


@dataclass(frozen=True)
class Merge:
    """An identity recovery: from ``frame_index`` on, track ``source_id`` is reported as ``target_id``."""

    frame_index: int
    source_id: int
    target_id: int


@dataclass(frozen=True)
class DiverSortConfig:
    """Diver SORT's parameters (pixels, frames, cosine distances); validated on construction."""

    iou_shortcut: float = param(0.75, "IoU with last frame's detection that joins its track directly")
    appearance_threshold: float = param(0.10, "largest cosine cost of a match (paper 1e-4 for its features)")
    long_term_threshold: float = param(0.30, "threshold for tracks unseen > long_term_after (paper 5e-4)")
    location_gate: float = param(9.21, "largest squared Mahalanobis distance of the centre (paper 25)")
    location_weight: float = param(0.1, "weight of d²/location_gate added to tied costs")
    tie_margin: float = param(0.02, "tracks this close to a detection's best cost count as tied")
    long_term_after: int = param(5, "frames unseen after which only appearance is used")
    recent_first: bool = param(False, "match recently seen tracks before long-unseen ones (ours)")
    n_init: int = param(3, "consecutive matches that make a track an identity")
    recovery_window: int = param(15, "a track alive this many frames or fewer may be merged")
    recovery_fraction: float = param(0.25, "share of gallery pairs under the threshold that merges")
    recovery_threshold: float = param(0.30, "cosine distance counted as similar for recovery")
    gallery_size: int = param(100, "features kept per track")
    max_age: int | None = param(None, "frames a confirmed track survives unseen (None: forever)")
    position_std_frac: float = param(0.15, "centre measurement noise as a fraction of box height")
    accel_std_frac: float = param(1 / 20, "centre acceleration noise per frame, fraction of box height")
    frame_interval_s: float | None = param(None, "seconds per frame (None: the smallest step seen)")

    def __post_init__(self) -> None:
        check_positive(self, "iou_shortcut", "appearance_threshold", "long_term_threshold", "location_gate",
                       "n_init", "recovery_window", "gallery_size", "max_age", "position_std_frac",
                       "accel_std_frac", "frame_interval_s")
        check_positive(self, "location_weight", "tie_margin", "long_term_after", allow_zero=True)
        check_positive(self, "recovery_threshold", "recovery_fraction", allow_zero=True)
        if self.iou_shortcut > 1 or self.recovery_fraction >= 1:
            raise ValueError("Config.iou_shortcut must be <= 1 and recovery_fraction < 1")
