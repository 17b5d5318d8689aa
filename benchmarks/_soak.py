"""A soak run of the node on loopback: a random mix of valid and invalid datagrams for a while,
then a clean final frame whose team state is known (``node_soak.py`` runs it; the tests import it too).

The node runs in a thread of this process with :class:`LatestHeadingMatcher` as its tracker (each
detection goes to the robot whose latest reported heading is closest), so the final team state
can be predicted exactly. :func:`soak` returns what was sent, the node's counters, the largest
queue and table sizes seen, resident memory, and whether the final team state was right.
"""

from __future__ import annotations

import json
import logging
import math
import threading
import time
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from lookalike._lsap import linear_sum_assignment
from lookalike.node.client import Endpoint
from lookalike.node.identifier import IdentifierConfig
from lookalike.node.messages import (
    MAX_DATAGRAM_BYTES,
    SCHEMA_VERSION,
    DetectionsMessage,
    HeadingReport,
    Status,
    StatusRequest,
    TeamState,
)
from lookalike.node.server import NodeConfig, NodeServer
from lookalike.types import Frame, TrackSnapshot, TrackStatus

# Datagram outcomes that exclude each other: every datagram read falls under exactly one.
EXCLUSIVE = ("rate_limited", "reports", "late", "duplicate", "unknown_robot", "time_backwards", "queue_full",
             "frames", "frame_backwards", "time_ahead", "other_camera", "status_requests", "tracker_errors",
             "handler_errors")


class LatestHeadingMatcher:
    """A memory-light identifier for the soak: each frame, detections are assigned (Hungarian on
    the circular heading difference, radians) to the robots' latest reported headings."""

    def __init__(self, n_robots: int) -> None:
        self.n_robots = n_robots
        self.reset()

    def reset(self) -> None:
        """Forget the headings."""
        self.heading = np.full(self.n_robots, np.nan)
        self.sent = np.full(self.n_robots, -np.inf)

    def update(self, frame: Frame) -> list[TrackSnapshot]:
        """Identify ``frame``'s detections."""
        b = frame.beacons
        for a, t, h in zip(b.agent_id.tolist(), b.t_sent.tolist(), b.heading.tolist()):
            if t >= self.sent[a]:
                self.heading[a], self.sent[a] = h, t
        known = np.flatnonzero(np.isfinite(self.heading))
        det = frame.detections
        if not len(det) or not len(known) or det.heading is None or det.position is None:
            return []
        diff = np.abs(np.angle(np.exp(1j * (det.heading[:, None] - self.heading[None, known]))))
        rows, cols = linear_sum_assignment(diff)
        return [TrackSnapshot(track_id=int(known[c]) + 1, status=TrackStatus.CONFIRMED, position=det.position[r],
                              heading=float(det.heading[r]), agent_id=int(known[c]),
                              identity_prob=float(1 - diff[r, c] / np.pi), detection_index=int(r))
                for r, c in zip(rows, cols)]


@dataclass
class SoakResult:
    """What a soak run sent and saw (memory in MB; sizes are the largest seen while sampling)."""

    seconds: float
    sent: dict[str, int] = field(default_factory=dict)
    counters: dict[str, Any] = field(default_factory=dict)
    max_queued: int = 0
    max_buckets: int = 0
    rss_start_mb: float = math.nan
    rss_peak_mb: float = math.nan
    alive: bool = False
    final_team: TeamState | None = None
    final_ok: bool = False

    def consistent(self) -> bool:
        """Every datagram read falls under exactly one outcome, and no more were read than sent."""
        c = self.counters
        outcomes = sum(int(c.get(name, 0)) for name in EXCLUSIVE) + int(c.get("rejected_total", 0))
        return c.get("received") == outcomes and 0 < c.get("received", 0) <= sum(self.sent.values())

    def summary(self) -> dict[str, Any]:
        """JSON-ready figures."""
        return {"seconds": round(self.seconds, 1), "sent": self.sent, "received": self.counters.get("received"),
                "rejected": self.counters.get("rejected"), "max_queued": self.max_queued,
                "max_buckets": self.max_buckets, "rss_start_mb": round(self.rss_start_mb, 1),
                "rss_peak_mb": round(self.rss_peak_mb, 1), "alive": self.alive, "consistent": self.consistent(),
                "final_ok": self.final_ok}


def rss_mb() -> float:
    """Resident memory of this process in MiB (2**20 bytes; NaN where /proc is missing)."""
    try:
        with open("/proc/self/statm") as fh:
            pages = int(fh.read().split()[1])
    except (OSError, ValueError, IndexError):
        return math.nan
    import resource

    return pages * resource.getpagesize() / 2**20


def _invalid(rng: np.random.Generator, now: float) -> bytes:
    """One invalid datagram of a random kind."""
    kind = int(rng.integers(0, 14))
    report = {"v": SCHEMA_VERSION, "type": "report", "robot": 0, "seq": 1, "t_sent": now, "heading": 0.0}
    if kind == 0:
        return rng.bytes(int(rng.integers(0, 300)))
    if kind == 1:
        return json.dumps({**report, "seq": int(rng.choice([2**63, 2**64 + 7, -1]))}).encode()
    if kind == 2:
        return json.dumps({**report, "t_sent": 10**400}).encode()
    if kind == 3:
        return b'{"v": 1, "type": "report", "robot": 0, "seq": 1, "t_sent": NaN, "heading": 0}'
    if kind == 4:
        return b"[" * 5000 + b"]" * 5000
    if kind == 5:
        return b"x" * (MAX_DATAGRAM_BYTES + 1)
    if kind == 6:
        return json.dumps({**report, "v": 99}).encode()
    if kind == 7:
        return json.dumps({"v": SCHEMA_VERSION, "type": "launch"}).encode()
    if kind == 8:
        return json.dumps({"v": SCHEMA_VERSION, "type": "team", "frame": 0, "time": 0.0, "robots": [],
                           "labels": []}).encode()
    if kind == 9:
        n = 300
        return json.dumps({"v": SCHEMA_VERSION, "type": "detections", "frame": 1, "time": now,
                           "position": [[0, 0]] * n, "heading": [0] * n, "score": [1] * n}).encode()
    if kind == 10:
        return json.dumps({**report, "extra": "x" * 1000}).encode()
    if kind == 11:
        return json.dumps({**report, "heading": "north"}).encode()
    if kind == 12:
        return json.dumps({"v": SCHEMA_VERSION, "type": "detections", "frame": 1, "time": now,
                           "position": [[0, 0]], "heading": [0, 1], "score": [1]}).encode()
    return "\udcff".encode("utf-8", "surrogatepass")


def soak(seconds: float, seed: int = 0, n_robots: int = 3, n_ports: int = 40) -> SoakResult:
    """Run the node for ``seconds`` wall seconds under a random mix of datagrams from ``n_ports``
    loopback ports (valid and invalid reports, frames, floods, status requests), then check a
    clean final frame. Loopback only; bounded in time."""
    rng = np.random.default_rng(seed)
    result = SoakResult(seconds=seconds)
    sent = {"valid_reports": 0, "invalid": 0, "frames": 0, "status_requests": 0, "flood_reports": 0}
    subscriber = Endpoint(("127.0.0.1", 1))
    id_config = IdentifierConfig(n_robots=n_robots, max_queued_per_robot=64, max_queued=128)
    quiet = logging.getLogger("lookalike.node.soak")  # (camera_lost and the like are expected here)
    quiet.propagate = False
    if not quiet.handlers:
        quiet.addHandler(logging.NullHandler())
    node = NodeServer(LatestHeadingMatcher(n_robots),
                      NodeConfig(publish=(subscriber.address,), reply_to_robots=False, status_interval_s=0,
                                 max_senders=64, camera_timeout_s=0.5),
                      id_config, logger=quiet)
    stop = threading.Event()
    thread = threading.Thread(target=node.serve, args=(stop.is_set, 0.01), daemon=True)
    thread.start()
    ports = [Endpoint(node.address) for _ in range(n_ports)]
    result.rss_start_mb = result.rss_peak_mb = rss_mb()
    frame, sim, seqs = 0, 0.0, [0] * (n_robots + 2)
    try:
        t_end = time.monotonic() + seconds
        next_sample = 0.0
        while time.monotonic() < t_end:
            sim += 0.005
            port = ports[int(rng.integers(0, n_ports))]
            roll = rng.random()
            if roll < 0.35:
                robot = int(rng.integers(0, n_robots + 2))  # some ids are outside the team
                seqs[robot] += int(rng.integers(-1, 3))  # duplicates, reordering, restarts
                port.send(HeadingReport(robot=robot, seq=max(seqs[robot], 0), t_sent=sim - rng.uniform(0, 2),
                                        heading=float(rng.uniform(-math.pi, math.pi))))
                sent["valid_reports"] += 1
            elif roll < 0.7:
                port.send_bytes(_invalid(rng, sim))
                sent["invalid"] += 1
            elif roll < 0.85:
                frame += 1 if rng.random() < 0.95 else -3  # sometimes backwards
                n = int(rng.integers(0, 6))
                camera = ports[0] if rng.random() < 0.95 else port  # the camera, and now and then another sender
                camera.send(DetectionsMessage(frame=max(frame, 0), time=max(frame, 0) * 0.033, heading=tuple(
                    rng.uniform(-3, 3, n).tolist()), position=tuple((float(i), 0.0) for i in range(n)),
                    score=(1.0,) * n))
                sim = max(sim, max(frame, 0) * 0.033)
                sent["frames"] += 1
            elif roll < 0.97:
                port.send(StatusRequest())
                sent["status_requests"] += 1
            else:  # a flood of valid reports with increasing numbers from one port (beyond its burst)
                robot = int(rng.integers(0, n_robots))
                for _ in range(600):
                    seqs[robot] += 1
                    port.send(HeadingReport(robot=robot, seq=seqs[robot], t_sent=sim, heading=0.0))
                sent["flood_reports"] += 600
            if time.monotonic() >= next_sample:
                next_sample = time.monotonic() + 0.1
                result.max_queued = max(result.max_queued, node.identifier.queued)
                result.max_buckets = max(result.max_buckets, len(node._buckets))
                result.rss_peak_mb = max(result.rss_peak_mb, rss_mb())
                time.sleep(0.002)  # let the node's thread catch up now and then
        _, asks = _ask_status(node)  # (the node has read everything sent before its reply)
        sent["status_requests"] += asks
        result.final_team, final_expected = _final_frame(node, subscriber, n_robots, frame + 1000, sim + 10.0)
        result.final_ok = result.final_team is not None and _matches(result.final_team, final_expected)
        sent["final"] = n_robots + 2
        status, asks = _ask_status(node)
        sent["status_requests"] += asks
        result.alive = thread.is_alive() and status is not None
        result.counters = status if status is not None else node.counters.snapshot()
        result.sent = sent
    finally:
        stop.set()
        thread.join(5)
        for p in ports:
            p.close()
        subscriber.close()
        node.close()
    result.rss_peak_mb = max(result.rss_peak_mb, rss_mb())
    return result


def _final_frame(node: NodeServer, subscriber: Endpoint, n_robots: int, frame: int,
                 t: float) -> tuple[TeamState | None, tuple[tuple[int, ...], tuple[tuple[float, float], ...]]]:
    """Fresh robots report distinct headings, the camera sends a frame holding them in reverse
    order; returns the team state the subscriber received and the (labels, positions) expected."""
    headings = [-2.5 + 5.0 * j / max(n_robots - 1, 1) for j in range(n_robots)]
    order = list(reversed(range(n_robots)))
    positions = tuple((10.0 + k, -1.0 * k) for k in range(n_robots))
    subscriber.drain()
    time.sleep(1.5 * node.config.camera_timeout_s)  # the mix's camera falls silent: a new camera is accepted
    with Endpoint(node.address) as robots, Endpoint(node.address) as camera:
        # an empty frame first takes the reports still queued from the mix
        camera.send(DetectionsMessage(frame=frame - 1, time=t - 0.5, position=(), heading=(), score=()))
        for j in range(n_robots):
            robots.send(HeadingReport(robot=j, seq=2**62 + j, t_sent=t - 0.01, heading=headings[j]))
        camera.send(DetectionsMessage(frame=frame, time=t, position=positions,
                                      heading=tuple(headings[j] for j in order), score=(1.0,) * n_robots))
        deadline = time.monotonic() + 10.0
        while time.monotonic() < deadline:
            message = subscriber.receive(0.5)
            if isinstance(message, TeamState) and message.frame == frame:
                by_robot = tuple(positions[order.index(j)] for j in range(n_robots))
                return message, (tuple(order), by_robot)
    return None, ((), ())


def _matches(team: TeamState, expected: tuple[tuple[int, ...], tuple[tuple[float, float], ...]]) -> bool:
    labels, positions = expected
    return team.labels == labels and tuple(r.position for r in team.robots) == positions \
        and [r.id for r in team.robots] == list(range(len(positions)))


def _ask_status(node: NodeServer) -> tuple[dict[str, Any] | None, int]:
    """The node's counters (None without a reply) and how many requests that took."""
    with Endpoint(node.address) as ask:
        for k in range(1, 21):
            ask.send(StatusRequest())
            message = ask.receive(0.5)
            if isinstance(message, Status):
                return message.counters, k
    return None, 20


__all__ = ["EXCLUSIVE", "LatestHeadingMatcher", "SoakResult", "rss_mb", "soak"]
