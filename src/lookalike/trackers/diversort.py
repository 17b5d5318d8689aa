"""DiverSORT: appearance-first tracking of look-alike divers with long-term re-identification; the diver-tracking
paper's seven mechanisms (defaults and their sources: docs/trackers/diversort.md):

1. IoU shortcut: a detection overlapping a track's previous detection by ``iou_shortcut`` joins it first.
2. Centre-only Kalman filter on ``(x, y, vx, vy)`` (pixels); box size from the latest detection.
3. Cost: minimum cosine distance to the track's gallery, plus ``location_weight · d²/location_gate`` where tracks tie
   within ``tie_margin``; pairs beyond ``location_gate`` (squared Mahalanobis) or ``appearance_threshold`` excluded.
4. Tentative tracks: confirmed after ``n_init`` consecutive matches, deleted at their first miss.
5. Long-term re-identification: tracks unseen over ``long_term_after`` frames match on appearance alone.
6. Identity recovery: a young confirmed track merges into an older lost one with enough gallery distances below
   ``recovery_threshold`` (:attr:`DiverSort.merges`).
7. Persistent identities: at most ``max_lost`` unseen confirmed tracks are kept."""

from __future__ import annotations

from typing import ClassVar

import numpy as np

from lookalike.association.appearance import FeatureGallery, require_features
from lookalike.association.stages import Stage, run_plan
from lookalike.geometry.boxes import iou_matrix
from lookalike.motion import kalman
from lookalike.motion.spaces import CentreCV
from lookalike.trackers.base import NEEDS_APPEARANCE
from lookalike.trackers.diversort_config import DiverSortConfig, Merge
from lookalike.trackers.parts.lifecycle import Lifecycle
from lookalike.trackers.parts.table import TrackTable
from lookalike.trackers.parts.timing import FrameClock
from lookalike.trackers.registry import register_tracker
from lookalike.types import Frame, Tracks, TrackStatus

__all__ = ["DiverSort", "DiverSortConfig", "Merge"]

_MOTION = ("mean", "cov", "box", "hits", "misses", "last_seen")  # what a merged track takes from its source


@register_tracker("diversort")
class DiverSort:
    """Diver SORT on boxes (pixels) and appearance features (``frame.detections.feature``)."""

    Config = DiverSortConfig
    needs: ClassVar[str] = NEEDS_APPEARANCE

    def __init__(self, config: DiverSortConfig | None = None) -> None:
        self.config = cfg = config or DiverSortConfig()
        self._space = CentreCV(cfg.position_std_frac, cfg.accel_std_frac)
        self._lifecycle = Lifecycle(n_init=cfg.n_init, tentative_max_misses=1, max_misses=cfg.max_age)
        self.reset()

    def reset(self) -> None:
        """Forget every track and merge; ids restart at 1."""
        # hits: consecutive matches; box: the latest matched detection; born/last_seen: frame numbers
        self._tracks = TrackTable(4, {"box": ((4,), float), "born": ((), int), "last_seen": ((), int)})
        self._gallery = FeatureGallery(self.config.gallery_size)
        self._frame = -1
        self._clock = FrameClock(self.config.frame_interval_s)
        self.merges: list[Merge] = []
        self.shortcut_matches = 0  # detections matched by the IoU shortcut (a diagnostic)

    def uncertain(self, track_id: int) -> bool:
        """True while a track, tentative or confirmed, is young enough to be merged (its identity is not yet
        settled)."""
        t = self._tracks
        rows = np.flatnonzero(t.ids == track_id)
        return bool(len(rows)) and self._frame - int(t["born"][rows[0]]) < self.config.recovery_window

    def update(self, frame: Frame) -> Tracks:
        """Advance all tracks to ``frame`` and match its detections (which need ``feature``)."""
        cfg, t = self.config, self._tracks
        det = frame.detections
        det.require_sizes("diversort")
        features = require_features(det, "diversort")
        self._gallery.check(features)  # before any change: a refused frame leaves the tracks as they were
        self._frame += 1
        steps = self._clock.steps(frame.time)
        if len(t):
            t.mean, t.cov = self._space.predict(t.mean, t.cov, steps, t["box"][:, 3])
            t.age()
        centre = self._space.measure(det.xywh)
        every = np.ones(len(det), dtype=bool)

        def shortcut(r: np.ndarray, c: np.ndarray) -> np.ndarray:  # (1)
            iou = iou_matrix(t["box"][r], det.xywh[c])
            return np.where(iou >= cfg.iou_shortcut, 1.0 - iou, np.inf)

        def cost(r: np.ndarray, c: np.ndarray) -> np.ndarray:
            return self._cost(r, det.xywh[c], centre[c], features[c])

        long_term = t.misses > cfg.long_term_after
        groups = [~long_term, long_term] if cfg.recent_first else [np.ones(len(t), dtype=bool)]
        matching = run_plan([Stage(t.misses == 1, every, shortcut, name="IoU shortcut")]
                            + [Stage(g, every, cost, name="appearance") for g in groups], len(t), len(det))
        self.shortcut_matches += int((matching.stage_of_track == 0).sum())
        det_of_track = matching.det_of_track
        rows = np.flatnonzero(det_of_track >= 0)
        if len(rows):
            self._correct(rows, det.xywh[det_of_track[rows]], centre[det_of_track[rows]], features[det_of_track[rows]])
        keep = self._lifecycle.alive(t) & self._within_lost_cap()
        self._keep(keep)
        det_of_track = det_of_track[keep]
        new = np.flatnonzero(matching.free)
        if len(new):
            mean, cov = self._space.initial(centre[new], det.xywh[new, 3])
            born = t.add(mean, cov, box=det.xywh[new], hits=1, born=self._frame, last_seen=self._frame,
                         confirmed=self._lifecycle.born_confirmed())
            for tid, feat in zip(t.ids[born], features[new]):
                self._gallery.add(int(tid), feat)
            det_of_track = np.concatenate([det_of_track, new])
        det_of_track = self._recover(frame.index, det_of_track)
        return self._report(det_of_track)

    # -- mechanisms --------------------------------------------------------------------------

    def _cost(self, rows: np.ndarray, xywh: np.ndarray, centre: np.ndarray, features: np.ndarray) -> np.ndarray:
        """(3, 5) ``(len(rows), n)`` costs of tracks ``rows`` for detections; ``inf`` unacceptable."""
        cfg, t = self.config, self._tracks
        appearance = self._gallery.min_distance(t.ids[rows], features)
        long_term = t.misses[rows] > cfg.long_term_after
        R = self._space.R(xywh[:, 3])  # per detection
        # Squared Mahalanobis distance with the innovation covariance of each (track, detection) pair.
        S = t.cov[rows][:, None, :2, :2] + R[None]
        diff = centre[None, :, :] - t.mean[rows][:, None, :2]
        maha = np.einsum("tdi,tdi->td", diff, np.linalg.solve(S, diff[..., None])[..., 0])
        short_ok = (maha <= cfg.location_gate) & (appearance <= cfg.appearance_threshold)
        long_ok = appearance <= cfg.long_term_threshold
        ok = np.where(long_term[:, None], long_ok, short_ok)
        cost = np.where(ok, appearance, np.inf)
        location = np.where(long_term[:, None], 1.0, np.minimum(maha / cfg.location_gate, 1.0))
        best = cost.min(axis=0)
        tied = (np.isfinite(cost) & (cost <= best + cfg.tie_margin)).sum(axis=0) > 1
        cost[:, tied] += cfg.location_weight * location[:, tied]
        return cost

    def _within_lost_cap(self) -> np.ndarray:
        """(7) Tracks kept: all but the longest-unseen confirmed ones beyond ``max_lost`` (ties: oldest id)."""
        cap, t = self.config.max_lost, self._tracks
        keep = np.ones(len(t), dtype=bool)
        if cap is None:
            return keep
        lost = np.flatnonzero(t.confirmed & (t.misses > 0))
        if len(lost) > cap:
            order = lost[np.lexsort((t.ids[lost], t["last_seen"][lost]))]
            keep[order[: len(lost) - cap]] = False
        return keep

    def _recover(self, frame_index: int, det_of_track: np.ndarray) -> np.ndarray:
        """(6) Merge young confirmed tracks into identities unseen since their birth."""
        cfg, t = self.config, self._tracks
        born = t["born"]
        young = np.flatnonzero(t.confirmed & (self._frame - born < cfg.recovery_window) & (t.misses == 0))
        for source in t.ids[young[np.argsort(born[young], kind="stable")]]:
            row = int(np.flatnonzero(t.ids == source)[0])
            candidates = np.flatnonzero(t.confirmed & (t["last_seen"] < t["born"][row]))
            if not len(candidates):
                continue
            share = np.array([self._gallery.pair_fraction_below(int(source), int(t.ids[c]), cfg.recovery_threshold)
                              for c in candidates])
            if share.max() <= cfg.recovery_fraction:
                continue
            target = int(candidates[share.argmax()])
            t.copy_row(row, target, _MOTION)
            self._gallery.merge(int(t.ids[row]), int(t.ids[target]))
            det_of_track[target] = det_of_track[row]
            self.merges.append(Merge(frame_index, int(source), int(t.ids[target])))
            keep = np.ones(len(t), dtype=bool)
            keep[row] = False
            self._keep(keep)
            det_of_track = det_of_track[keep]
        return det_of_track

    # -- state -------------------------------------------------------------------------------

    def _correct(self, rows: np.ndarray, xywh: np.ndarray, centre: np.ndarray, features: np.ndarray) -> None:
        t = self._tracks
        t.mean[rows], t.cov[rows] = kalman.update(t.mean[rows], t.cov[rows], centre, self._space.H,
                                                  self._space.R(xywh[:, 3]))
        t["box"][rows] = xywh
        t.hits[rows] = np.where(t.misses[rows] == 1, t.hits[rows] + 1, 1)
        t.misses[rows] = 0
        t["last_seen"][rows] = self._frame
        self._lifecycle.confirm(t, rows)
        for row, feat in zip(rows, features):
            self._gallery.add(int(t.ids[row]), feat)

    def _report(self, det_of_track: np.ndarray) -> Tracks:
        t = self._tracks
        idx = np.flatnonzero(t.confirmed & (t.misses == 0))
        return Tracks(t.ids[idx], TrackStatus.CONFIRMED, xywh=self._space.box(t.mean[idx], t["box"][idx]),
                      velocity=t.mean[idx, 2:] / self._clock.interval, detection_index=det_of_track[idx])

    def _keep(self, mask: np.ndarray) -> None:
        for tid in self._tracks.ids[~mask]:
            self._gallery.remove(int(tid))
        self._tracks.keep(mask)
