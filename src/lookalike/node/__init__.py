"""The observer node: a UDP service that receives robots' heading reports and a camera's detections, identifies the
robots with any registered tracker, and publishes their positions at the camera rate."""

from lookalike.node.client import Endpoint
from lookalike.node.counters import EVENTS, NodeCounters, log_event
from lookalike.node.identifier import (
    IdentifierConfig,
    TeamIdentifier,
)
from lookalike.node.messages import (
    SCHEMA_VERSION,
    DetectionsMessage,
    HeadingReport,
    MessageError,
    RobotEstimate,
    Status,
    StatusRequest,
    TeamState,
    decode,
    encode,
)
from lookalike.node.server import NodeConfig, NodeServer, parse_address

__all__ = [
    "EVENTS",
    "SCHEMA_VERSION",
    "DetectionsMessage",
    "Endpoint",
    "HeadingReport",
    "IdentifierConfig",
    "MessageError",
    "NodeConfig",
    "NodeCounters",
    "NodeServer",
    "RobotEstimate",
    "Status",
    "StatusRequest",
    "TeamIdentifier",
    "TeamState",
    "decode",
    "encode",
    "log_event",
    "parse_address",
]
