"""The world trackers' shared base: ground positions (observer frame, metres), one constant-acceleration Kalman filter
per track, beacon identification. Kalman-HA, Kalman-HA2 and JPDA differ in their rules and association."""

from __future__ import annotations

from typing import ClassVar, NamedTuple

import numpy as np

from lookalike.motion import chi2_gate
from lookalike.motion.models import constant_acceleration
from lookalike.motion.spaces import WorldCA
from lookalike.trackers.base import NEEDS_ROBOTS
from lookalike.trackers.kernels.world import (
    cholesky,
    compiled,
    decided_pairs,
    einsum,
    filled,
    lower_solve_exact,
    pairs,
    solve,
    update_exact,
)
from lookalike.trackers.parts.identity import BeaconIdentifier, IdentifierConfig
from lookalike.trackers.parts.table import TrackTable
from lookalike.trackers.parts.timing import RESET_HINT
from lookalike.trackers.parts.world_rules import WorldConfig, WorldRules, headings, positions
from lookalike.types import Detections, Frame, Tracks

H = WorldCA.H


class WorldTracker:
    """The world trackers' frame loop; they differ in :class:`WorldRules` and :meth:`_associate_and_update`
    (returns the detection index per track, -1 for a miss)."""

    name: ClassVar[str] = "world"
    needs: ClassVar[str] = NEEDS_ROBOTS

    def __init__(self, config: WorldConfig, rules: WorldRules) -> None:
        self.config = config
        self.rules = rules
        self._gate = chi2_gate(2, config.gate_probability)
        self._space = WorldCA(config.q_jerk, config.meas_std0_m, config.meas_std_per_m,
                              config.init_velocity_std, config.init_accel_std)
        self.reset()

    def reset(self) -> None:
        """Forget every track; ids restart at 1."""
        cfg = self.config
        self._tracks = TrackTable(6, {"hit_bits": ((), np.int64)})  # hit history, bit 0 = this frame
        self._time: float | None = None
        # per frame interval (s): F, F.T, Q and the coasting velocity factor (None: no decay)
        self._models: dict[float, tuple[np.ndarray, np.ndarray, np.ndarray, float | None]] = {}
        self._intervals: list[float] = []  # the last two distinct frame intervals (> 0 s), the latest first
        self._repeated: set[float] = set()  # those of them that came again while in that list
        self._ready: dict[float, _Prepared] = {}  # the next frame's prediction per interval (prepare)
        self._frame_ready: _Prepared | None = None  # the one this frame uses
        self._identifier = BeaconIdentifier(IdentifierConfig(
            n_agents=cfg.n_agents, window_frames=cfg.window_frames, max_cost=cfg.max_identity_cost,
            hysteresis=cfg.hysteresis))

    # -- the frame loop ----------------------------------------------------------------------

    def update(self, frame: Frame) -> Tracks:
        """Predict, associate, update, manage the lifecycle, identify; return the reported tracks."""
        det, t = frame.detections, self._tracks
        if len(det) and (det.position is None or det.heading is None):
            raise ValueError(f"frame {frame.index}: {self.name} needs detections with position and heading")
        dt = 0.0 if self._time is None else frame.time - self._time
        if dt < 0:
            raise ValueError(f"frame {frame.index}: time went backwards ({self._time} s then {frame.time} s)"
                             f"{RESET_HINT}")
        self._identifier.begin_frame(frame.time, frame.beacons)  # (first: it refuses unknown agents, changing nothing)
        self._time = frame.time
        if dt > 0:
            if dt in self._intervals:
                self._repeated.add(dt)
            if not self._intervals or dt != self._intervals[0]:
                self._intervals = [dt, *self._intervals[:1]]
                self._repeated.intersection_update(self._intervals)
        ready, self._ready = self._ready.get(dt), {}  # (made for this interval from this table: prepare)
        if ready is not None:
            t.mean, t.cov = ready.mean, ready.cov
        elif len(t) and dt != 0:
            t.mean, t.cov = self._predicted(t.mean, t.cov, dt)
        self._frame_ready = ready
        det_of_track = self._associate_and_update(det)
        det_of_track = self._lifecycle(det_of_track, dt, None if ready is None else ready.in_view)
        new = self._birth_candidates(det, det_of_track)
        if len(new):
            mean, cov = self._space.initial(positions(det)[new])
            self._tracks.add(mean, cov, hit_bits=1, confirmed=self.rules.born_confirmed)  # (_lifecycle may replace it)
        return self._report(det, np.concatenate([det_of_track, new]))

    # -- steps -------------------------------------------------------------------------------

    def prepare(self) -> None:
        """Between frames (optional; the node calls it): predict the tracks and the detection-independent parts of the
        next association for each of the last two distinct intervals seen more than once; :meth:`update` uses them
        when its interval matches exactly (same bits). JPDA prepares nothing."""
        t = self._tracks
        self._ready = {}
        if (self._time is None or not len(t)
                or type(self)._associate_and_update is not WorldTracker._associate_and_update):
            return
        for dt in self._intervals:
            if dt not in self._repeated:
                continue
            mean, cov = self._predicted(t.mean.copy(), t.cov, dt)
            S = cov[:, :2, :2] + self._space.R(mean[:, :2])
            in_view = None if self.rules.confirm_window is None else self.rules.in_view(mean[:, :2])
            self._ready[dt] = _Prepared(mean, cov, S, cholesky(S), *self._gains(S, cov), in_view)

    def _predicted(self, mean: np.ndarray, cov: np.ndarray, dt: float) -> tuple[np.ndarray, np.ndarray]:
        """The predicted means and covariances over ``dt`` > 0 seconds (``mean``'s coasting rows are
        decayed in place first)."""
        model = self._models.get(dt)
        if model is None:  # (WorldCA.predict's model and the decay, kept for the latest intervals)
            F, Q = constant_acceleration(2, dt, self.config.q_jerk)
            decay_s = self.rules.coast_decay_s
            model = F, F.T, Q, None if decay_s is None else np.exp(-dt / decay_s)
            if len(self._models) > 3:
                self._models = {k: v for k, v in self._models.items() if k in self._intervals}
            self._models[dt] = model
        F, Ft, Q, decay = model  # (kalman.predict's arithmetic, its transposes made once per interval)
        if decay is not None:
            coasting = self._tracks.misses > 0
            if coasting.any():
                mean[coasting, 2:4] *= decay
                mean[coasting, 4:6] = 0.0
        return mean @ Ft, F @ cov @ Ft + Q

    @staticmethod
    def _gains(S: np.ndarray, cov: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The solve of ``S K = H P`` (``(k, 2, 6)``: the Kalman gains transposed) for innovation covariances
        ``S (k, 2, 2)`` and covariances ``cov (k, 6, 6)``, and the covariances after an update."""
        PHt_T = np.ascontiguousarray(cov[:, :, :2]).swapaxes(-1, -2)  # (``(P @ H.T).T``, (k, 2, 6))
        gain = solve(S, PHt_T)
        return gain, cov - gain.swapaxes(-1, -2) @ PHt_T

    def _associate_and_update(self, det: Detections) -> np.ndarray:
        """Hungarian on the gated squared Mahalanobis distance; Kalman update of matched tracks.

        ``motion.kalman``'s arithmetic on the whole table at once (``H`` picks the position, so ``H P Hᵀ`` and ``P Hᵀ``
        are slices of ``P``); uses :meth:`prepare`'s values when the frame found them."""
        t, ready = self._tracks, self._frame_ready
        det_of_track = filled(len(t), -1, int)
        if not (len(t) and len(det)):
            return det_of_track
        z = positions(det)
        mean, cov = t.mean, t.cov
        if ready is not None:
            S, L = ready.S, ready.L
        else:
            S = cov[:, :2, :2] + self._space.R(mean[:, :2])
            L = cholesky(S)
        kernels = compiled()
        # (with LAPACK's 2×2 solve replicated bit for bit (world_kernels.lower_solve_exact), the innovations,
        # their whitening and pairs' steps up to the solver in one compiled call; -1: not plain numbers)
        gated = kernels.gate_work_lower(L, z, mean, self._gate) if kernels and lower_solve_exact(len(z)) else None
        if gated is not None and gated[0] >= 0:
            rows, cols = decided_pairs(*gated)
        else:
            y = solve(L, (z[None, :, :] - mean[:, None, :2]).swapaxes(-1, -2))  # (k, 2, d)
            if kernels is not None:  # (the lines below and pairs' steps up to the solver, in one compiled call)
                rows, cols = decided_pairs(*kernels.gate_work(y, self._gate))
            else:
                d2 = np.add.reduce(y * y, axis=1)
                rows, cols = pairs(d2, d2 <= self._gate)
        det_of_track[rows] = cols
        if len(rows) and ready is not None and kernels is not None and update_exact():  # (below, one call)
            kernels.update_hits(t.mean, t.cov, rows, cols, ready.gain, ready.cov_hit, z)
        elif len(rows):  # (with the gains and covariances made ahead when prepared)
            gain, cov_hit = (ready.gain[rows], ready.cov_hit[rows]) if ready is not None else self._gains(
                S[rows], cov[rows])
            m = mean[rows]
            t.mean[rows] = m + einsum("kij,kj->ki", gain.swapaxes(-1, -2), z[cols] - m[:, :2])
            t.cov[rows] = cov_hit
        return det_of_track

    def _lifecycle(self, det_of_track: np.ndarray, dt: float, in_view: np.ndarray | None = None) -> np.ndarray:
        """Record the frame's hits and misses (``dt`` seconds), confirm and delete tracks; return ``det_of_track`` of
        the survivors. ``in_view``: which tracks were predicted in view (:meth:`prepare`)."""
        t, rules = self._tracks, self.rules
        window = rules.confirm_window
        if window is not None and in_view is None:
            in_view = rules.in_view(t.mean[:, :2])
        kernels, life = compiled(), rules.lifecycle
        if kernels is not None and life.max_unseen_s is life.tentative_max_unseen_s is None and not life.closed:
            # (the lines below and Lifecycle.alive's in one compiled call, in place on the columns)
            keep = kernels.lifecycle_work(
                det_of_track, t["hit_bits"], t.misses, t.unseen_s, t.hits, t.confirmed, dt,
                0 if window is None else window, life.n_init,
                -1 if life.tentative_max_misses is None else life.tentative_max_misses,
                -1 if life.max_misses is None else life.max_misses, _NO_VIEW if in_view is None else in_view,
                rules.max_coast_s + 1e-9, rules.max_out_of_view_s + 1e-9)
        else:
            hit = det_of_track >= 0
            t["hit_bits"] = ((t["hit_bits"] << 1) | hit) & ((1 << 30) - 1)
            t.record(hit, dt)
            limit_s = None
            if window is None:
                t.confirmed[:] = True
            else:
                t.hits = bit_count(t["hit_bits"] & ((1 << window) - 1))
                life.confirm(t)
                assert in_view is not None  # (made above when there is a confirmation window)
                limit_s = np.where(in_view, rules.max_coast_s + 1e-9, rules.max_out_of_view_s + 1e-9)
            keep = life.alive(t, limit_s)
        if not keep.all():
            self._identifier.drop(t.ids[~keep])
            t.keep(keep)
        survivors: np.ndarray = det_of_track[keep]
        return survivors

    def _birth_candidates(self, det: Detections, det_of_track: np.ndarray) -> np.ndarray:
        """Indices of detections that start tracks."""
        t, rules = self._tracks, self.rules
        kernels = compiled()
        if kernels is not None and len(det):  # (the lines below in one compiled call)
            min_score, exclusion_m = rules.birth_min_score, rules.birth_exclusion_m
            new_rows: np.ndarray = kernels.birth_candidates(
                det_of_track, det.score, 0.0 if min_score is None else min_score, min_score is not None,
                positions(det), t.mean, 0.0 if exclusion_m is None else exclusion_m, exclusion_m is not None)
            return new_rows
        free = np.ones(len(det) + 1, dtype=bool)  # (the extra last entry takes the misses' -1)
        free[det_of_track] = False
        free = free[:-1]
        if len(det) and rules.birth_min_score is not None:
            free &= det.score >= rules.birth_min_score
        new = np.flatnonzero(free)
        if len(new) and rules.birth_exclusion_m is not None and len(t):
            # distance to the nearest track, as np.linalg.norm computes it: sqrt of the summed squares
            diff = positions(det)[new][:, None, :] - t.mean[None, :, :2]
            gap = np.sqrt(np.add.reduce(diff * diff, axis=2))
            new = new[np.minimum.reduce(gap, axis=1) > rules.birth_exclusion_m]
        return new

    def _report(self, det: Detections, det_of_track: np.ndarray) -> Tracks:
        """Identify (the visual headings of this frame's hits and births go to the identifier
        first) and report every track."""
        t = self._tracks
        k = len(t)
        seen = det_of_track >= 0
        if len(det):
            heading = headings(det)[det_of_track]  # (a miss's -1 reads the last heading: replaced by NaN)
            if seen.all():
                self._identifier.observe_many(t.ids.tolist(), heading)
            else:
                if seen.any():
                    self._identifier.observe_many(t.ids[seen].tolist(), heading[seen])
                heading[~seen] = np.nan  # (heading: a new array, from the fancy index)
        else:
            heading = np.full(k, np.nan)
        confirmed = t.confirmed
        if confirmed.all():
            agent, prob = self._identifier.assign_arrays(t.ids.tolist())  # (new arrays)
        else:
            agent = filled(k, -1, int)
            prob = filled(k, np.nan)
            agent[confirmed], prob[confirmed] = self._identifier.assign_arrays(t.ids[confirmed].tolist())
        out = Tracks.__new__(Tracks)  # (columns built here: Tracks' checks skipped)
        out.id, out.xywh, out.detection_index = t.ids.copy(), None, det_of_track
        out.status = np.left_shift(confirmed, ~seen, dtype=np.int8)  # 0 tentative, 1 confirmed, 2 lost
        out.position, out.velocity = t.mean[:, :2].copy(), t.mean[:, 2:4].copy()
        out.heading, out.agent_id, out.identity_prob = heading, agent, prob
        return out


class _Prepared(NamedTuple):
    """:meth:`WorldTracker.prepare`'s prediction for one interval: means ``(k, 6)``, covariances, ``S (k, 2, 2)`` and
    its Cholesky factors, gains transposed ``(k, 2, 6)``, covariances after an update, in view (None: no rules)."""

    mean: np.ndarray
    cov: np.ndarray
    S: np.ndarray
    L: np.ndarray
    gain: np.ndarray
    cov_hit: np.ndarray
    in_view: np.ndarray | None


_NO_VIEW = np.zeros(0, dtype=bool)  # (the compiled lifecycle's in-view argument when there are no view rules)

_BITWISE_COUNT = getattr(np, "bitwise_count", None)


def bit_count(bits: np.ndarray) -> np.ndarray:
    """Set bits of each non-negative integer below 2**32 (``np.bitwise_count``, which numpy < 2 lacks)."""
    if _BITWISE_COUNT is not None:
        return np.asarray(_BITWISE_COUNT(bits)).astype(int)
    as_bytes = np.ascontiguousarray(bits, dtype=np.uint32).view(np.uint8).reshape(len(bits), 4)
    counts: np.ndarray = np.unpackbits(as_bytes, axis=1).sum(axis=1).astype(int)
    return counts
