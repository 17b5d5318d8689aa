"""Track identities from the agents' self-reports (DESIGN §5) and per-detection labels."""

from lookalike.trackers.parts.identity.beacon import BeaconIdentifier, IdentifierConfig
from lookalike.trackers.parts.identity.labels import agent_positions, labels_from_tracks

__all__ = ["BeaconIdentifier", "IdentifierConfig", "agent_positions", "labels_from_tracks"]
