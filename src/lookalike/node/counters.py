"""The node's counters, publish latencies and structured (JSON Lines) log events."""

from __future__ import annotations

import json
import logging
from collections import Counter, deque
from typing import Any

import numpy as np

# What the node counts, besides the rejection reasons of lookalike.node.messages.
EVENTS = (
    "received",  # datagrams read from the socket
    "reports",  # heading reports accepted
    "frames",  # detection frames accepted and tracked
    "published",  # team-state datagrams sent
    "status_requests",  # status requests answered
    "late",  # reports older than the newest one of that robot, or too old for the current frame
    "duplicate",  # a report or frame seen already (same sequence number / frame index)
    "unknown_robot",  # reports from a robot id outside the team
    "time_backwards",  # a report whose send time goes back for an increasing sequence number
    "queue_dropped",  # accepted reports pushed out of their robot's full queue before a frame came
    "queue_full",  # reports dropped because the queues of all robots together were full
    "frame_backwards",  # a detection frame older than the last one (dropped)
    "time_ahead",  # a frame or report whose time is too far after the camera's last frame (dropped)
    "other_camera",  # a detection frame from another sender while the camera is alive (dropped)
    "robot_resets",  # robots whose sequence and clock were forgotten: their last report was ahead of a new frame
    "camera_lost",  # the camera went silent for longer than the timeout
    "camera_restarts",  # the camera came back with an earlier time: the tracker was reset
    "rate_limited",  # datagrams dropped because their sender exceeded its packet rate
    "send_errors",  # team-state datagrams the OS refused to send
    "tracker_errors",  # frames the tracker raised on (dropped; the node goes on)
    "handler_errors",  # datagrams the node itself failed on (a bug; logged, the node goes on)
)


class NodeCounters:
    """Counts of every event and rejection reason, and latencies and CPU times of the last ``window`` frames."""

    def __init__(self, window: int = 1000) -> None:
        self.events: Counter[str] = Counter({name: 0 for name in EVENTS})
        self.rejected: Counter[str] = Counter()
        self.latency_s: deque[float] = deque(maxlen=window)
        self.cpu_s: deque[float] = deque(maxlen=window)  # the node thread's CPU time per published frame
        # the same plus the CPU time of preparing the next frame after the send (between frames)
        self.cpu_with_prepare_s: deque[float] = deque(maxlen=window)

    def add(self, event: str, count: int = 1) -> None:
        """Count ``event`` (one of ``EVENTS``)."""
        if event not in self.events:
            raise ValueError(f"event: unknown counter {event!r}; known: {list(EVENTS)}")
        self.events[event] += count

    def reject(self, reason: str) -> None:
        """Count a datagram rejected for ``reason``."""
        self.rejected[reason] += 1

    def snapshot(self) -> dict[str, Any]:
        """All counters as a JSON-ready dict; ``latency_ms`` (wall time from reading a frame to its last send),
        ``cpu_ms`` and ``cpu_with_prepare_ms`` (also preparing the next frame) in milliseconds."""
        out: dict[str, Any] = dict(self.events)
        out["rejected"] = dict(sorted(self.rejected.items()))
        out["rejected_total"] = sum(self.rejected.values())
        for name, values in (("latency_ms", self.latency_s), ("cpu_ms", self.cpu_s),
                             ("cpu_with_prepare_ms", self.cpu_with_prepare_s)):
            if values:
                ms = np.asarray(values) * 1e3
                out[name] = {"median": round(float(np.median(ms)), 4),
                             "p99": round(float(np.percentile(ms, 99)), 4), "frames": len(ms)}
        return out

    def status_line(self) -> str:
        """One human-readable line: the main counts and the latency."""
        e = self.events
        line = (f"received {e['received']} reports {e['reports']} frames {e['frames']} published {e['published']} "
                f"rejected {sum(self.rejected.values())} late {e['late']} duplicate {e['duplicate']} "
                f"rate-limited {e['rate_limited']}")
        if self.latency_s:
            lat = np.asarray(self.latency_s) * 1e3
            line += f" latency median {np.median(lat):.2f} ms p99 {np.percentile(lat, 99):.2f} ms"
        return line


def log_event(logger: logging.Logger, event: str, level: int = logging.INFO, **fields: Any) -> None:
    """Log one structured event as a JSON object ``{"event": ..., **fields}``."""
    if logger.isEnabledFor(level):
        logger.log(level, json.dumps({"event": event, **fields}, separators=(",", ":"), default=str))
