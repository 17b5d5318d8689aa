"""Which two agents' heading reports have exchanged robots (ids swapped, or a swap undone), even when the
two headings differ by less than a robot can turn between two reports.

Each agent's reports (absolute heading, radians, at their send time) feed a constant-turn-rate Kalman
filter that runs ``lag_s`` seconds behind the newest report of any agent, so that the reports just after an
exchange are compared with heading tracks that have not absorbed them yet. For every new report of agent
``a`` and every other agent ``b``, the log-likelihood ratio of "this report continues b's track" over "it
continues a's own" is summed (a CUSUM: never below 0) and decays with time constant ``memory_s``, so that
evidence one stream left long ago (two robots heading alike) does not complete an exchange later; a track
that has had no report for a while (a lost burst) takes no part. When the sums of ``(a, b)`` and of
``(b, a)`` together pass twice ``threshold`` and each passes a quarter of it, each stream continues the
other's track (a robot that starts to turn just then may fit neither, so one stream can carry most of the
evidence): the two tracks are exchanged and the pair is returned. One stream alone (a robot turning fast)
does not pass, as the other keeps fitting its own track. With ``step_rad``, an exchange also needs both
streams to have stepped within the last ``step_window_s`` seconds: a report that departs by more than
``step_rad`` from the agent's previous report carried on at its track's turn rate. An exchange of ids is such a
step in both streams at once; two robots that turn smoothly onto each other's headings are not.
"""

from __future__ import annotations

from collections import deque

import numpy as np


def _wrap(angle: np.ndarray) -> np.ndarray:
    return (angle + np.pi) % (2 * np.pi) - np.pi


class ReportExchange:
    """Exchange detector over ``n`` agents' heading reports (see the module)."""

    def __init__(self, n: int, threshold: float, accel_psd: float = 0.1, lag_s: float = 0.4,
                 noise_rad: float = float(np.radians(2.0)), memory_s: float | None = 1.0,
                 fresh_s: float | None = 0.6, step_rad: float | None = None, step_window_s: float = 1.0) -> None:
        """``threshold``: half the log-likelihood ratio the two streams must pass together; ``accel_psd``: spectral
        density of the heading's angular acceleration, rad²/s³; ``lag_s``: how far the tracks run behind the
        newest report of any agent, seconds; ``noise_rad``: a report's heading noise (standard deviation), radians;
        ``memory_s``: time constant of the evidence's decay, seconds (None: no decay); ``fresh_s``: a track
        whose newest report is older than ``lag_s`` + ``fresh_s`` seconds takes no part (None: every track);
        ``step_rad``: the step both streams need within ``step_window_s`` seconds, radians (None: none needed)."""
        self.n, self.threshold, self.q, self.lag_s, self.r = n, threshold, accel_psd, lag_s, noise_rad ** 2
        self.memory_s = memory_s
        self.oldest = np.inf if fresh_s is None else lag_s + fresh_s  # oldest usable track, seconds
        self.clock = -np.inf  # newest send time seen, seconds
        self.x = np.zeros((n, 2))  # heading (rad), turn rate (rad/s) at self.t
        self.p = np.zeros((n, 2, 2))
        self.t = np.full(n, np.nan)  # time of each track's state; NaN: no track yet
        self.newest = np.full(n, -np.inf)  # send time of each agent's newest report
        self.queue: list[deque[tuple[float, float]]] = [deque() for _ in range(n)]
        self.evidence = np.zeros((n, n))  # [a, b]: evidence that a's reports continue b's track
        self.step_rad, self.step_window_s = step_rad, step_window_s
        self.last = np.full((n, 2), np.nan)  # each agent's newest report: send time (s), heading (rad)
        self.stepped = np.full(n, -np.inf)  # send time of each agent's newest step

    def _predict(self, t: float) -> tuple[np.ndarray, np.ndarray]:
        """Every track's heading (rad) and its variance plus the report noise at time ``t`` (NaN: none)."""
        dt = t - self.t
        var = (self.p[:, 0, 0] + 2 * dt * self.p[:, 0, 1] + dt * dt * self.p[:, 1, 1]
               + self.q * np.abs(dt) ** 3 / 3 + self.r)
        return self.x[:, 0] + self.x[:, 1] * dt, var

    def _update(self, a: int, t: float, heading: float) -> None:
        """Advance agent ``a``'s track to ``t`` and correct it with ``heading``."""
        if np.isnan(self.t[a]):
            self.x[a], self.p[a], self.t[a] = (heading, 0.0), np.diag([self.r, 1.0]), t
            return
        dt = t - self.t[a]
        f = np.array([[1.0, dt], [0.0, 1.0]])
        q = self.q * np.array([[dt ** 3 / 3, dt ** 2 / 2], [dt ** 2 / 2, dt]])
        x, p = f @ self.x[a], f @ self.p[a] @ f.T + q
        gain = p[:, 0] / (p[0, 0] + self.r)
        x = x + gain * float(_wrap(np.asarray(heading - x[0])))
        self.x[a] = (float(_wrap(np.asarray(x[0]))), x[1])
        self.p[a], self.t[a] = p - np.outer(gain, p[0]), t

    def add(self, agent: int, t_sent: float, heading: float, scale: np.ndarray | None = None) -> tuple[int, int] | None:
        """Take one report (send time in seconds, absolute heading in radians); a report not newer than the
        agent's newest is ignored; ``scale`` (n) a factor on the threshold of the agent's pair with each other agent
        (None: 1). Returns the exchanged pair ``(agent, other)`` when this report completes an exchange (the two
        tracks are exchanged already), else None."""
        a = agent
        if not (t_sent > self.newest[a] and np.isfinite(heading)):
            return None
        self.newest[a] = t_sent
        self._note_step(a, t_sent, heading)
        if t_sent > self.clock:
            if np.isfinite(self.clock) and self.memory_s is not None:
                self.evidence *= np.exp(-(t_sent - self.clock) / self.memory_s)
            self.clock = t_sent
        for c in range(self.n):
            queue = self.queue[c]
            while queue and queue[0][0] < t_sent - self.lag_s:
                self._update(c, *queue.popleft())
        self.queue[a].append((t_sent, heading))
        if np.isnan(self.t[a]):
            return None
        mean, var = self._predict(t_sent)
        nu2 = _wrap(heading - mean) ** 2 / var
        gain = 0.5 * (nu2[a] - nu2) - 0.5 * np.log(var / var[a])
        known = t_sent - self.t <= self.oldest  # NaN (no track yet): False
        if not known[a]:
            return None
        known[a] = False
        row = self.evidence[a]
        row[known] = np.maximum(row[known] + gain[known], 0.0)
        col = self.evidence[:, a]
        threshold = self.threshold if scale is None else self.threshold * scale
        both = known & (row + col > 2 * threshold) & (np.minimum(row, col) > threshold / 4)
        if self.step_rad is not None:
            both &= (t_sent - self.stepped <= self.step_window_s) & (t_sent - self.stepped[a] <= self.step_window_s)
        if not both.any():
            return None
        b = int(np.argmax(np.where(both, row + col, -np.inf)))
        self.swap(a, b)
        return a, b

    def _note_step(self, a: int, t_sent: float, heading: float) -> None:
        """Keep agent ``a``'s newest report and note a step (see the module) at ``t_sent`` (only with ``step_rad``)."""
        if self.step_rad is None:
            return
        t_last, h_last = self.last[a]
        if np.isfinite(t_last):
            rate = 0.0 if np.isnan(self.t[a]) else self.x[a, 1]
            if abs(float(_wrap(np.asarray(heading - h_last - rate * (t_sent - t_last))))) > self.step_rad:
                self.stepped[a] = t_sent
        self.last[a] = t_sent, heading

    def swap(self, a: int, b: int) -> None:
        """Exchange the tracks of agents ``a`` and ``b`` and clear their evidence: their report streams now
        continue each other's. Their queued reports straddle the exchange and are dropped (the tracks predict
        over the gap)."""
        for arr in (self.x, self.p, self.t):
            arr[[a, b]] = arr[[b, a]]
        self.queue[a].clear()
        self.queue[b].clear()
        self.evidence[[a, b], :] = 0.0
        self.evidence[:, [a, b]] = 0.0
        self.stepped[[a, b]] = -np.inf

    def forget(self, a: int) -> None:
        """Start agent ``a``'s track afresh from its next report (its reports now come from a robot no other
        agent reported for) and clear its evidence."""
        self.t[a] = np.nan
        self.queue[a].clear()
        self.evidence[a, :] = 0.0
        self.evidence[:, a] = 0.0
        self.last[a], self.stepped[a] = np.nan, -np.inf
