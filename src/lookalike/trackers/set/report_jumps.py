"""Which agents' heading reports jumped to another robot, and with which agent they exchanged robots.

A report jumping more than ``jump`` + ``turn_rate`` · the time since the agent's previous one means it now reports for
another robot: exchanged with the one agent that reported the new heading just before, else with the agent whose jump
mirrors it within :data:`PAIR_WAIT_S` seconds (forgotten when none comes). A report after a long silence that is off
by more than ``jump`` is paired only with a mirroring waiting jump. :meth:`ReportJumps.find` returns the actions."""

from __future__ import annotations

import numpy as np

from lookalike.geometry.angles import wrap_angle

PAIR_WAIT_S = 1.0  # how long a jump without a partner waits for its mirror, seconds
SAME_EXCHANGE_S = 1.0  # a partner's own jump within this long after an exchange is the same exchange, seconds

Waiting = dict[int, tuple[float, float, float]]  # agent -> (old heading, new heading (radians), time of its jump, s)
Action = tuple[int, int] | np.ndarray  # (a, b): exchange the two agents' memories; an array: forget these agents


class ReportJumps:
    """Report jumps over the agents' newest reports (see the module)."""

    def __init__(self, jump: float, turn_rate: float) -> None:
        self.jump, self.turn_rate = jump, turn_rate
        self.expected: dict[int, float] = {}  # agent -> send time of the exchange whose second half it awaits
        self.pending: Waiting = {}  # jumps waiting for their mirror
        self.silent: Waiting = {}  # first reports after a silence waiting for their mirror, never forgotten

    def find(self, old: np.ndarray, t_old: np.ndarray, new: np.ndarray, t_new: np.ndarray,
             now: float) -> list[Action]:
        """The actions on the agents' memories, in order, from each agent's previous newest report (``old`` heading,
        sent at ``t_old`` s) and its newest now (``new``, ``t_new``), at frame time ``now``."""
        actions: list[Action] = []
        fresh = np.isfinite(old) & np.isfinite(new) & (t_new > t_old)
        if fresh.any():
            step = np.exp(1j * (new - old))
            turn = np.abs(np.arctan2(step.imag, step.real))  # (np.angle's arithmetic)
            gap = np.where(fresh, t_new - np.where(fresh, t_old, 0.0), 0.0)
            jumped = fresh & (turn > self.jump + self.turn_rate * gap)
            if jumped.any():
                self._swap(np.flatnonzero(jumped), old, t_old, new, t_new, actions)
            silence = fresh & ~jumped & (turn > self.jump)
            if silence.any():
                self._after_silence(np.flatnonzero(silence), old, new, t_new, actions)
        if self.pending or self.silent:  # waiting jumps expire after PAIR_WAIT_S: forgotten, or (silent) dropped
            wait = PAIR_WAIT_S
            self.silent = {a: v for a, v in self.silent.items() if now - v[2] <= wait}
            expired = [a for a, (_, _, t) in self.pending.items() if now - t > wait]
            if expired:
                for a in expired:
                    del self.pending[a]
                actions.append(np.array(expired))
        return actions

    def exchanged(self, pair: tuple[int, int], t_sent: float) -> None:
        """Another rule exchanged ``pair`` on a report sent at ``t_sent`` s: a jump of either agent within
        :data:`SAME_EXCHANGE_S` is the same exchange, and neither waits any more."""
        for j in pair:
            self.expected[j] = t_sent
            self.pending.pop(j, None)
            self.silent.pop(j, None)

    def _swap(self, jumped: np.ndarray, old: np.ndarray, t_old: np.ndarray, new: np.ndarray, t_new: np.ndarray,
              actions: list[Action]) -> None:
        """Each agent ``a`` of ``jumped`` exchanges memories with its mirror among the waiting jumps, else with the one
        agent ``b`` that reported its new heading just before (whose own jump then changes nothing), else waits."""
        done: set[int] = set()
        for a in jumped.tolist():
            if a in done:
                continue
            if t_new[a] - self.expected.pop(a, -np.inf) <= SAME_EXCHANGE_S:
                continue  # the second half of a swap already made
            heading = float(new[a])
            self.pending.pop(a, None)
            b = self._mirror(a, float(old[a]), heading, float(t_new[a]), self.pending)
            if b is None and self.silent:
                b = self._mirror(a, float(old[a]), heading, float(t_new[a]), self.silent)
            if b is not None:
                actions.append((a, b))
                continue
            turn = np.abs(np.angle(np.exp(1j * (heading - old))))
            match = np.isfinite(old) & (turn <= self.jump + self.turn_rate * np.abs(t_new[a] - t_old))
            match[a] = False
            partners = np.flatnonzero(match)
            if len(partners) != 1:
                self.pending[a] = (float(old[a]), heading, float(t_new[a]))
                continue
            b = int(partners[0])
            actions.append((a, b))
            if b in jumped:
                done.add(b)
            else:
                self.expected[b] = t_new[a]

    def _after_silence(self, agents: np.ndarray, old: np.ndarray, new: np.ndarray, t_new: np.ndarray,
                       actions: list[Action]) -> None:
        """Each of ``agents`` reports after a silence a heading over ``jump`` off its previous one: exchanged with a
        mirroring waiting jump, else it waits too (dropped later without forgetting anything)."""
        for c in agents.tolist():
            if c in self.pending:
                continue
            heading = float(new[c])
            b = self._mirror(c, float(old[c]), heading, float(t_new[c]), self.pending)
            if b is not None:
                actions.append((c, b))
            else:
                self.silent[c] = (float(old[c]), heading, float(t_new[c]))

    def _mirror(self, a: int, old: float, new: float, t: float, waiting: Waiting) -> int | None:
        """The closest agent in ``waiting`` (removed from it) mirroring ``a``'s jump from ``old`` to ``new`` at ``t``
        seconds within ``jump`` + ``turn_rate`` · the time between them (None: none)."""
        best, best_error = None, np.inf
        for c, (old_c, new_c, t_c) in waiting.items():
            if c == a:
                continue
            tolerance = self.jump + self.turn_rate * abs(t - t_c)
            errors = np.abs(wrap_angle(np.array([new - old_c, new_c - old])))
            if errors.max() <= tolerance and errors.sum() < best_error:
                best, best_error = c, float(errors.sum())
        if best is not None:
            del waiting[best]
        return best
