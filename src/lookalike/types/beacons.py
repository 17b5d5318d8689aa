"""``Beacons``: self-reports (e.g. IMU headings) that agents broadcast about themselves."""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from lookalike.types._validate import as_column, reject_unknown, require_finite

_EMPTY: Beacons | None = None


@dataclass(frozen=True, eq=False)
class Beacons:
    """Reports received since the previous frame, one row per report.

    Attributes:
        agent_id: ``(n,)`` integer id of the reporting agent (0-based).
        t_sent: ``(n,)`` time the agent sent the report, seconds.
        t_received: ``(n,)`` time the observer received it, seconds.
        heading: ``(n,)`` the agent's own absolute heading in radians."""

    agent_id: np.ndarray
    t_sent: np.ndarray
    t_received: np.ndarray
    heading: np.ndarray

    def __post_init__(self) -> None:
        own = "Beacons"
        agent = np.asarray(self.agent_id)
        n = int(agent.shape[0]) if agent.ndim > 0 else 0
        object.__setattr__(self, "agent_id", as_column(own, "agent_id", self.agent_id, n, None, int))
        if (self.agent_id < 0).any():
            row = int(np.flatnonzero(self.agent_id < 0)[0])
            raise ValueError(f"{own}.agent_id: row {row} is negative ({self.agent_id[row]})")
        for name in ("t_sent", "t_received", "heading"):
            arr = as_column(own, name, getattr(self, name), n, None)
            require_finite(own, name, arr)
            object.__setattr__(self, name, arr)

    def __len__(self) -> int:
        return int(self.agent_id.shape[0])

    def require_agents(self, n_agents: int) -> None:
        """``ValueError`` for a report from an agent id outside ``0 .. n_agents - 1`` (a tracker of ``n_agents``)."""
        if len(self.agent_id) and int(self.agent_id.max()) >= n_agents:
            raise ValueError(f"Beacons.agent_id: {int(self.agent_id.max())} is no agent of this tracker "
                             f"(n_agents={n_agents}: ids 0 to {n_agents - 1})")

    @classmethod
    def empty(cls) -> Beacons:
        """No reports (one shared, read-only instance)."""
        global _EMPTY
        if _EMPTY is None:
            z = np.zeros(0)
            _EMPTY = cls(agent_id=np.zeros(0, dtype=int), t_sent=z, t_received=z, heading=z)
        return _EMPTY

    @classmethod
    def from_dict(cls, columns: Mapping[str, Any]) -> Beacons:
        """Build from a mapping of column name to values; unknown names raise ``ValueError``."""
        reject_unknown("Beacons", dict(columns), tuple(f.name for f in dataclasses.fields(cls)))
        return cls(**columns)
