"""Which two agents' heading reports have exchanged robots (ids swapped, or a swap undone), even when the two headings
differ by less than a robot can turn between two reports.

Each agent's reports feed a constant-turn-rate Kalman filter running ``lag_s`` behind the newest report of any agent.
Each new report of agent ``a`` adds, for every other agent ``b``, the log-likelihood ratio of "it continues b's track"
over "it continues a's own" to a CUSUM decaying with time constant ``memory_s``. When the sums of ``(a, b)`` and
``(b, a)`` pass twice ``threshold`` together and each a quarter of it, the two tracks are exchanged and the pair
returned (one stream alone, a robot turning fast, does not pass). :func:`for_team` builds the detector ``set`` runs."""

from __future__ import annotations

import math
from collections import deque

import numpy as np

ACCEL_PSD = 0.1  # spectral density of a robot heading's angular acceleration, rad²/s³
LAG_S = 0.4  # how far the report tracks run behind the newest report, seconds
TIGHT_TEAM = 5  # teams of at least this many agents use the smoother model below
TIGHT_ACCEL_PSD = 0.03  # rad²/s³
TIGHT_LAG_S = 0.3  # seconds
NOISE_RAD = 0.035  # a heading report's noise (standard deviation), radians
MEMORY_S = 1.0  # time constant of the evidence's decay, seconds
MAX_AGENTS = 7  # larger teams run no report-exchange detector


def _wrap(angle: np.ndarray) -> np.ndarray:
    return (angle + np.pi) % (2 * np.pi) - np.pi


def _wrap_float(angle: float) -> float:
    """:func:`_wrap` of one angle (radians; the same arithmetic on a Python float)."""
    return (angle + math.pi) % (2 * math.pi) - math.pi


class ReportExchange:
    """Exchange detector over ``n`` agents' heading reports (see the module)."""

    def __init__(self, n: int, threshold: float, accel_psd: float = ACCEL_PSD, lag_s: float = LAG_S,
                 noise_rad: float = NOISE_RAD, memory_s: float = MEMORY_S) -> None:
        """Parameters as in the module; ``accel_psd``: the heading's angular acceleration, rad²/s³; ``noise_rad``: a
        report's heading noise (standard deviation)."""
        self.n, self.threshold, self.q, self.lag_s, self.r = n, threshold, accel_psd, lag_s, noise_rad ** 2
        self.memory_s = memory_s
        self.clock = -np.inf  # newest send time seen, seconds
        self.x = np.zeros((n, 2))  # heading (rad), turn rate (rad/s) at self.t
        self.p = np.zeros((n, 2, 2))
        self.t = np.full(n, np.nan)  # time of each track's state; NaN: no track yet
        self.newest = np.full(n, -np.inf)  # send time of each agent's newest report
        self.queue: list[deque[tuple[float, float]]] = [deque() for _ in range(n)]
        self.evidence = np.zeros((n, n))  # [a, b]: evidence that a's reports continue b's track

    def _predict(self, t: float) -> tuple[np.ndarray, np.ndarray]:
        """Every track's heading (rad) and its variance plus the report noise at time ``t`` (NaN: none)."""
        dt = t - self.t
        var = (self.p[:, 0, 0] + 2 * dt * self.p[:, 0, 1] + dt * dt * self.p[:, 1, 1]
               + self.q * np.abs(dt) ** 3 / 3 + self.r)
        return self.x[:, 0] + self.x[:, 1] * dt, var

    def _update(self, a: int, t: float, heading: float) -> None:
        """Advance agent ``a``'s track to ``t`` and correct it with ``heading``."""
        t_a = float(self.t[a])
        if math.isnan(t_a):
            self.x[a], self.p[a], self.t[a] = (heading, 0.0), np.diag([self.r, 1.0]), t
            return
        dt = t - t_a
        f = np.array([[1.0, dt], [0.0, 1.0]])
        psd, q3, q2 = self.q, dt ** 3 / 3, dt ** 2 / 2
        q = np.array([[psd * q3, psd * q2], [psd * q2, psd * dt]])
        (x0, x1), ((p00, p01), (p10, p11)) = (f @ self.x[a]).tolist(), (f @ self.p[a] @ f.T + q).tolist()
        s = p00 + self.r  # (the gain and correction on floats: numpy's elementwise arithmetic, the same values)
        g0, g1 = p00 / s, p10 / s
        w = _wrap_float(heading - x0)
        self.x[a] = (_wrap_float(x0 + g0 * w), x1 + g1 * w)
        self.p[a] = ((p00 - g0 * p00, p01 - g0 * p01), (p10 - g1 * p00, p11 - g1 * p01))
        self.t[a] = t

    def add(self, agent: int, t_sent: float, heading: float, scale: np.ndarray | None = None) -> tuple[int, int] | None:
        """Take one report (send time s, heading rad; ignored unless newer than the agent's newest); ``scale (n,)``: a
        factor on the threshold of each pair with ``agent`` (None: 1). Returns the pair ``(agent, other)`` when this
        report completes an exchange (the tracks exchanged already), else None."""
        a = agent
        if not (t_sent > self.newest[a] and math.isfinite(heading)):
            return None
        self.newest[a] = t_sent
        if t_sent > self.clock:
            if np.isfinite(self.clock):
                self.evidence *= np.exp(-(t_sent - self.clock) / self.memory_s)
            self.clock = t_sent
        oldest = t_sent - self.lag_s
        for c, queue in enumerate(self.queue):
            while queue and queue[0][0] < oldest:
                self._update(c, *queue.popleft())
        self.queue[a].append((t_sent, heading))
        if math.isnan(self.t[a]):
            return None
        mean, var = self._predict(t_sent)
        nu2 = _wrap(heading - mean) ** 2 / var
        gain = 0.5 * (nu2[a] - nu2) - 0.5 * np.log(var / var[a])
        known = ~np.isnan(self.t)  # agents with a track
        known[a] = False
        row = self.evidence[a]
        row[:] = np.where(known, np.maximum(row + gain, 0.0), row)
        col = self.evidence[:, a]
        threshold = self.threshold if scale is None else self.threshold * scale
        both = known & (row + col > 2 * threshold) & (np.minimum(row, col) > threshold / 4)
        if not both.any():
            return None
        b = int(np.argmax(np.where(both, row + col, -np.inf)))
        self.swap(a, b)
        return a, b

    def swap(self, a: int, b: int) -> None:
        """Exchange the tracks of agents ``a`` and ``b``, clear their evidence and drop their queued reports."""
        for arr in (self.x, self.p, self.t):
            arr[[a, b]] = arr[[b, a]]
        self.queue[a].clear()
        self.queue[b].clear()
        self.evidence[[a, b], :] = 0.0
        self.evidence[:, [a, b]] = 0.0

    def forget(self, a: int) -> None:
        """Start agent ``a``'s track afresh from its next report and clear its evidence."""
        self.t[a] = np.nan
        self.queue[a].clear()
        self.evidence[a, :] = 0.0
        self.evidence[:, a] = 0.0


def for_team(n: int, threshold: float) -> ReportExchange | None:
    """The detector ``set`` runs for ``n`` agents: smoother turning (``TIGHT_*``) from :data:`TIGHT_TEAM` agents, none
    beyond :data:`MAX_AGENTS`."""
    if n > MAX_AGENTS:
        return None
    if n >= TIGHT_TEAM:
        return ReportExchange(n, threshold, TIGHT_ACCEL_PSD, TIGHT_LAG_S)
    return ReportExchange(n, threshold)
