"""Track lifecycle: the status enum (defined with the types) and confirmation counting."""

from __future__ import annotations

from lookalike.types.tracks import TrackStatus

__all__ = ["TrackStatus"]
