"""The beacon identifier: which of the N reporting agents each track is, by the Hungarian method on the cost
``(1 - cos(φ_i(t) - ψ_j(t))) / 2`` averaged over the last ``window_frames`` frames with a visual heading ``φ_i``;
``ψ_j(t)``: agent ``j``'s reports interpolated, or extrapolated at their turn rate (at most ``max_turn_rate``) for at
most ``max_extrapolation_s``. A track's current agent costs ``hysteresis`` less; pairs above ``max_cost`` are not
assigned; the identity probability is ``1 - cost``."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from lookalike.trackers.kernels.world import compiled, decided_pairs, filled, pairs
from lookalike.types import Beacons


@dataclass(frozen=True)
class IdentifierConfig:
    """Parameters of :class:`BeaconIdentifier` (frames, seconds, radians, costs in [0, 1])."""

    n_agents: int = 3
    window_frames: int = 30
    max_cost: float = 0.3
    hysteresis: float = 0.08
    history: int = 16
    max_extrapolation_s: float = 1.0
    max_turn_rate: float = 3.0

    def __post_init__(self) -> None:
        if self.n_agents < 0 or self.window_frames < 1 or self.history < 2:
            raise ValueError(f"IdentifierConfig: need n_agents >= 0, window_frames >= 1, history >= 2; got {self}")
        for name in ("max_cost", "hysteresis", "max_extrapolation_s", "max_turn_rate"):
            if getattr(self, name) < 0:
                raise ValueError(f"IdentifierConfig.{name} must be >= 0, got {getattr(self, name)}")


class BeaconIdentifier:
    """Identifies tracks with reporting agents; owns the report history and per-track windows."""

    def __init__(self, config: IdentifierConfig) -> None:
        self.config = config
        self.reset()

    def reset(self) -> None:
        """Forget reports, windows and identities."""
        n, r, w = self.config.n_agents, self.config.history, self.config.window_frames
        # report send times and headings, sorted by time, NaN padded at the front: _th[0] and _th[1]
        self._th = np.full((2, n, r), np.nan)
        self._t, self._h = self._th[0], self._th[1]  # (views)
        self._offset = np.arange(n) * r  # flat index of each agent's row in _t / _h
        self._times = np.full(w, np.nan)  # frame times of the ring
        self._times_count = np.full(w, np.inf)  # the same, +inf for no time (counts every report)
        self._slot = -1
        # per-track heading samples (row 0 all NaN: never observed), each row's agent (-1: none), track id -> row
        self._win = np.full((8, w), np.nan)
        self._current = np.full(8, -1, dtype=int)
        self._row: dict[int, int] = {}
        self._free: list[int] = list(range(7, 0, -1))

    # -- inputs ------------------------------------------------------------------------------

    def begin_frame(self, time_s: float, beacons: Beacons) -> None:
        """Start a frame at ``time_s``: store its received reports and open a window slot; ``ValueError`` for a report
        from an agent id outside ``0 .. n_agents - 1``."""
        r, n = self.config.history, self.config.n_agents
        agent_id = beacons.agent_id
        beacons.require_agents(n)
        if len(agent_id):
            kernels = compiled()
            if kernels is not None:  # (the common case, checked and shifted in one compiled call)
                shifted = bool(kernels.shift_reports(self._th, agent_id, beacons.t_sent, beacons.heading))
            else:
                shifted = self._shift_common(agent_id, beacons.t_sent, beacons.heading)
            if not shifted:
                for a in sorted(set(agent_id.tolist())):
                    mine = agent_id == a
                    self._store(a, beacons.t_sent[mine], beacons.heading[mine], r)
        self._slot = (self._slot + 1) % self.config.window_frames
        self._times[self._slot] = self._times_count[self._slot] = time_s
        self._win[:, self._slot] = np.nan

    def _shift_common(self, agent_id: np.ndarray, new_t: np.ndarray, heading: np.ndarray) -> bool:
        """:meth:`begin_frame`'s common case (one report per agent, each newer than those kept) as :meth:`_store`
        would do it; False, nothing changed, otherwise."""
        ids = agent_id.tolist()
        if len(set(ids)) < len(ids) or max(ids) >= self.config.n_agents or (new_t <= self._t[agent_id, -1]).any():
            return False
        th = self._th
        th[:, agent_id, :-1] = th[:, agent_id, 1:]
        th[0, agent_id, -1] = new_t
        th[1, agent_id, -1] = heading
        return True

    def _store(self, a: int, new_t: np.ndarray, new_h: np.ndarray, r: int) -> None:
        """Merge agent ``a``'s new reports into its history (sorted, duplicates dropped, last ``r``)."""
        t = np.concatenate([self._t[a], new_t])
        h = np.concatenate([self._h[a], new_h])
        known = np.isfinite(t)
        t, h = t[known], h[known]
        t, first = np.unique(t, return_index=True)  # sorted, duplicates dropped
        h = h[first]
        t, h = t[-r:], h[-r:]
        self._t[a] = np.nan
        self._h[a] = np.nan
        self._t[a, r - len(t):] = t
        self._h[a, r - len(h):] = h

    def observe(self, track_id: int, heading_rad: float) -> None:
        """Record the visual heading of track ``track_id`` in the current frame."""
        self.observe_many([track_id], np.array([heading_rad], dtype=float))

    def observe_many(self, track_ids: list[int], headings_rad: np.ndarray) -> None:
        """Record the visual headings ``(k,)`` of tracks ``track_ids`` in the current frame."""
        if self._slot < 0:
            raise ValueError("observe() before begin_frame()")
        if track_ids:
            rows = self._rows(track_ids)  # (may grow the table: before indexing it)
            self._win[rows, self._slot] = headings_rad

    def _rows(self, track_ids: list[int]) -> list[int]:
        """The sample rows of ``track_ids``, new rows (all NaN) for tracks not seen before."""
        rows = []
        get = self._row.get
        for track_id in track_ids:
            row = get(track_id)
            if row is None:
                if not self._free:
                    size = len(self._win)
                    self._win = np.concatenate([self._win, np.full_like(self._win, np.nan)])
                    self._current = np.concatenate([self._current, np.full(size, -1)])
                    self._free = list(range(2 * size - 1, size - 1, -1))
                row = self._row[track_id] = self._free.pop()
                self._win[row] = np.nan
                self._current[row] = -1
            rows.append(row)
        return rows

    def drop(self, track_ids: list[int] | np.ndarray) -> None:
        """Forget deleted tracks."""
        for t in np.asarray(track_ids).tolist():
            row = self._row.pop(int(t), None)
            if row is not None:
                self._free.append(row)

    # -- outputs -----------------------------------------------------------------------------

    def agent_headings(self, times_s: np.ndarray) -> np.ndarray:
        """Report-based headings ``(len(times), N)`` of every agent at ``times_s``; NaN where unknown."""
        q = np.asarray(times_s, dtype=float)
        return self._headings(q, np.where(np.isnan(q), np.inf, q))

    def _headings(self, q: np.ndarray, q_count: np.ndarray) -> np.ndarray:
        """:meth:`agent_headings` at times ``q`` for all agents at once; ``q_count``: ``q`` with NaN as +inf."""
        cfg = self.config
        n, r = self._t.shape
        if n == 0 or not len(q):
            return np.full((len(q), n), np.nan)
        k = np.add.reduce(self._t == self._t, axis=1)  # known reports per agent (NaN != NaN)
        if k.all():
            have, th, offset = None, self._th, self._offset
        else:
            have = np.flatnonzero(k)
            if not len(have):
                return np.full((len(q), n), np.nan)
            th, k, offset = self._th[:, have], k[have], self._offset[: len(have)]
        t, h = th[0], th[1]
        first = offset + (r - k)  # flat index of each agent's first known report
        # i: reports at or before each time (side="right"; NaN counts all, as in np.searchsorted)
        i = np.add.reduce(t[None, :, :] <= q_count[:, None, None], axis=2)  # (Q, A)
        at = i + first
        idx = np.empty((2,) + at.shape, dtype=np.intp)  # the reports before and after each time
        np.maximum(np.subtract(at, 1, out=idx[0]), first, out=idx[0])
        np.minimum(at, offset + (r - 1), out=idx[1])
        flat = th.reshape(2, -1)  # (a view: th is contiguous)
        (t_before, t_after), (h_before, h_after) = np.take(flat, idx, axis=1)
        span = t_after - t_before  # > 0 only between two reports, where 0 <= frac <= 1
        frac = np.divide(q[:, None] - t_before, span, out=filled(span.shape, 0.0), where=span > 0)
        inter = h_before + frac * _wrap(h_after - h_before)
        # extrapolation from the latest report with the turn rate of the last two (none with one)
        t_last, h_last, t_prev = t[:, -1], h[:, -1], t[:, -2]
        turning = t_last > t_prev  # (False with fewer than two reports: NaN)
        gap = np.where(turning, t_last - t_prev, 1.0)
        turn = _wrap(h_last - h[:, -2]) / gap
        rate = np.where(turning, np.minimum(np.maximum(turn, -cfg.max_turn_rate), cfg.max_turn_rate), 0.0)
        ahead = np.minimum(np.maximum(q[:, None] - t_last, 0.0), cfg.max_extrapolation_s)
        value: np.ndarray = np.where(i >= k, h_last + rate * ahead,
                                     np.where(i == 0, flat[1, first], inter))
        if have is None:
            return value
        out = np.full((len(q), n), np.nan)
        out[:, have] = value
        return out

    def costs(self, track_ids: list[int]) -> np.ndarray:
        """Cost matrix ``(len(track_ids), N)`` in [0, 1]; inf where no sample or no report."""
        get = self._row.get
        return self._costs([get(t, 0) for t in track_ids])

    def _costs(self, rows: list[int]) -> np.ndarray:
        n = self.config.n_agents
        if not rows or n == 0:
            return np.zeros((len(rows), n))
        samples = self._win[rows]
        kernels = compiled() if n > 1 else None  # (one agent: numpy sums the window pairwise)
        if kernels is not None:
            out = np.empty((len(rows), n))
            cfg = self.config
            kernels.window_costs(self._th, self._times, self._times_count, samples, cfg.max_turn_rate,
                                 cfg.max_extrapolation_s, out)
            return out
        agent = self._headings(self._times, self._times_count)  # (W, N)
        d = np.subtract(samples[:, :, None], agent[None])  # (k, W, N): (1 - cos(d)) / 2, in place
        np.cos(d, out=d)
        np.subtract(1.0, d, out=d)
        np.multiply(d, 0.5, out=d)  # (the same values as a division by 2: both exact scalings)
        count = np.add.reduce(np.isfinite(d), axis=1)
        total = np.add.reduce(np.fmax(d, 0.0, out=d), axis=1)  # (NaN -> 0; d >= 0 stays as it is)
        mean: np.ndarray = np.divide(total, count, out=filled(count.shape, np.inf), where=count > 0)
        return mean

    def assign(self, track_ids: list[int]) -> dict[int, tuple[int, float]]:
        """Identities of ``track_ids``: ``{track_id: (agent_id, probability)}`` for those assigned."""
        agent, prob = self.assign_arrays(track_ids)
        return {t: (a, p) for t, a, p in zip(track_ids, agent.tolist(), prob.tolist()) if a >= 0}

    def assign_arrays(self, track_ids: list[int]) -> tuple[np.ndarray, np.ndarray]:
        """:meth:`assign` as columns: agent id per track (-1: none) and probability (NaN: none)."""
        cfg = self.config
        k = len(track_ids)
        if not k:
            return filled(0, -1, int), filled(0, np.nan)
        get = self._row.get
        rows = [get(t, 0) for t in track_ids]
        kernels = compiled() if cfg.n_agents > 1 and cfg.max_cost <= 1.0 else None
        if kernels is not None:  # (the steps below in one compiled call up to the solver, one after it)
            index = np.array(rows)
            decision, cost, work, allowed = kernels.identity_rows_work(
                self._th, self._times, self._times_count, self._win, self._current, index, cfg.max_turn_rate,
                cfg.max_extrapolation_s, cfg.hysteresis, cfg.max_cost)
            r, a = decided_pairs(decision, work, allowed)
            found: tuple[np.ndarray, np.ndarray] = kernels.identity_results(r, a, cost, self._current, index)
            return found
        cost = self._costs(rows)
        biased = cost.copy()
        current = self._current[rows]
        held = np.flatnonzero(current >= 0)
        if len(held):  # (an infinite cost stays infinite)
            a = current[held]
            biased[held, a] = np.maximum(biased[held, a] - cfg.hysteresis, 0.0)
        r, a = pairs(biased, biased <= cfg.max_cost, cfg.max_cost, unit=True)  # (costs in [0, 1])
        agent_out = filled(k, -1, int)
        prob = filled(k, np.nan)
        agent_out[r] = a
        prob[r] = 1.0 - cost[r, a]
        self._current[rows] = agent_out  # (row 0, unobserved tracks, is never assigned: stays -1)
        return agent_out, prob


def _wrap(angle_rad: np.ndarray) -> np.ndarray:
    """:func:`lookalike.geometry.angles.wrap_angle` of an array (the same formula, fewer calls)."""
    wrapped: np.ndarray = np.pi - np.mod(np.pi - angle_rad, 2.0 * np.pi)
    return wrapped
