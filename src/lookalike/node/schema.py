"""The node's messages and their bounds: what each message holds (units: simulated seconds, metres in the observer
frame, radians), the limits every field is checked against, and the stable rejection codes. The wire format that encodes
and checks them is :mod:`lookalike.node.messages`."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

SCHEMA_VERSION = 1
MAX_DATAGRAM_BYTES = 65_000
MAX_DETECTIONS = 256
MAX_ROBOTS = 256  # robot estimates in one team state
MAX_INT = 2**63 - 1  # integers are 64-bit signed on the wire
MAX_ABS_NUMBER = 1e12  # |seconds|, |metres|, |radians|, scores: finite and at most this
MAX_COUNTERS = 256  # entries of a status message's counters (nested objects included)
MAX_KEY_CHARS = 64  # characters of a counter's name
MAX_DETAIL_CHARS = 80  # a rejected value is quoted in the error detail up to this many characters

# Rejection reasons (stable codes, counted by the node).
MALFORMED = "malformed"  # not UTF-8 JSON, or not a JSON object
TOO_LARGE = "too_large"
VERSION = "wrong_version"
UNKNOWN_TYPE = "unknown_type"
INVALID = "invalid"  # a field is missing, unknown, of the wrong type or out of range
UNEXPECTED = "unexpected_type"  # a valid message of a type the receiver does not take


class MessageError(ValueError):
    """A datagram that is not a valid message; ``reason`` is one of the codes above."""

    def __init__(self, reason: str, detail: str) -> None:
        super().__init__(f"{reason}: {detail}")
        self.reason = reason
        self.detail = detail


@dataclass(frozen=True)
class HeadingReport:
    """A robot's report of its own heading (robot -> node).

    Attributes:
        robot: robot id, 0-based.
        seq: the robot's message counter, increasing by one per report sent.
        t_sent: simulated time the robot sent the report, seconds.
        heading: the robot's absolute heading, radians."""

    robot: int
    seq: int
    t_sent: float
    heading: float


@dataclass(frozen=True)
class DetectionsMessage:
    """One camera frame of world-frame detections (camera -> node).

    Attributes:
        frame: frame index, 0-based.
        time: simulated time of the frame, seconds.
        position: ``n`` pairs ``[x, y]`` in metres.
        heading: ``n`` visual headings in radians.
        score: ``n`` detector confidences.
        heading_std: ``n`` spreads of the visual headings in radians, or None."""

    frame: int
    time: float
    position: tuple[tuple[float, float], ...]
    heading: tuple[float, ...]
    score: tuple[float, ...]
    heading_std: tuple[float, ...] | None = None


@dataclass(frozen=True)
class RobotEstimate:
    """The node's estimate of one robot.

    Attributes:
        id: robot id, 0-based.
        position: ``[x, y]`` metres.
        heading: radians, or None when unknown.
        confidence: identification confidence in [0, 1], or None.
        age: seconds since a detection last updated the estimate."""

    id: int
    position: tuple[float, float]
    heading: float | None
    confidence: float | None
    age: float


@dataclass(frozen=True)
class TeamState:
    """Identified positions after one camera frame (node -> robots and subscribers).

    Attributes:
        frame: the camera frame index.
        time: its simulated time, seconds.
        robots: one estimate per identified robot.
        labels: per detection of the frame, the robot id it was identified as (-1: none)."""

    frame: int
    time: float
    robots: tuple[RobotEstimate, ...]
    labels: tuple[int, ...] = ()


@dataclass(frozen=True)
class StatusRequest:
    """Ask the node for its counters; the reply goes to the sender."""


@dataclass(frozen=True)
class Status:
    """The node's counters (node -> requester)."""

    counters: dict[str, Any] = field(default_factory=dict)


Message = HeadingReport | DetectionsMessage | TeamState | StatusRequest | Status
