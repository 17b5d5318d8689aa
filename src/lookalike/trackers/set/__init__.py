"""The ``set`` identifier: one set-associator network for any number of agents, with the exchange detectors that
follow swaps of ids (:class:`~lookalike.trackers.set.tracker.SetIdentifier`)."""

from __future__ import annotations

from lookalike.trackers.set.tracker import SetIdentifier

__all__ = ["SetIdentifier"]
