"""The observer node's UDP server: one socket, a selector loop, per-sender rate limits. A frame's team state goes to
every ``publish`` address and to the multicast ``group`` or each robot's last address. The camera is the sender of the
last accepted frame: while it is alive, frames from others are dropped. Failures are counted and logged."""

from __future__ import annotations

import abc
import gc
import ipaddress
import logging
import selectors
import socket
import time
from collections.abc import Callable, Hashable
from dataclasses import dataclass
from typing import TypeVar

from lookalike.node.client import resolve_destination
from lookalike.node.counters import NodeCounters, log_event
from lookalike.node.identifier import IdentifierConfig, TeamIdentifier
from lookalike.node.messages import (
    UNEXPECTED,
    DetectionsMessage,
    HeadingReport,
    MessageError,
    Status,
    StatusRequest,
    TeamState,
    decode,
    encode,
)
from lookalike.parallel import one_blas_thread

Address = tuple[str, int]
LOCALHOST = "127.0.0.1"


def _preload() -> None:
    """Import what the first frame would otherwise import (scipy's solver, the world trackers' numba kernels)."""
    import numpy as np

    from lookalike.association.solver import linear_sum_assignment
    from lookalike.trackers.kernels.world import warm

    linear_sum_assignment(np.zeros((1, 1)))
    warm()


def parse_address(text: str, default_host: str = LOCALHOST) -> Address:
    """``HOST:PORT`` or ``PORT`` as ``(host, port)``; raises ``ValueError`` naming the text."""
    host, sep, port = text.rpartition(":")
    host = host if sep else default_host
    try:
        number = int(port)
    except ValueError:
        raise ValueError(f"address {text!r}: expected HOST:PORT with an integer port") from None
    if not 0 <= number <= 65535 or not host:
        raise ValueError(f"address {text!r}: port must be in 0..65535 and the host non-empty")
    return host, number


def check_group(group: Address) -> None:
    """Raise ``ValueError`` unless ``group`` is an IPv4 multicast address (224.0.0.0/4) with a port."""
    try:
        multicast = ipaddress.IPv4Address(group[0]).is_multicast
    except ValueError:
        multicast = False
    if not multicast or not 0 < group[1] <= 65535:
        raise ValueError(f"group {group[0]}:{group[1]}: expected an IPv4 multicast address "
                         "(224.0.0.0 to 239.255.255.255) and a port in 1..65535")


@dataclass(frozen=True)
class NodeConfig:
    """Network settings of the node.

    Attributes:
        listen: address to bind (port 0: an ephemeral port).
        publish: addresses that receive every team state (host names are looked up once, when the node starts).
        reply_to_robots: also send each team state to each robot's address (when there is no ``group``).
        group: an IPv4 multicast ``(group, port)`` that receives each team state in place of the per-robot replies.
        group_interface: IPv4 address of the interface multicast leaves from (loopback by default).
        sender_rate: packets per second one sender may send before being rate-limited.
        sender_burst: packets one sender may send at once (>= 1).
        max_senders: rate-limit buckets kept (the oldest are forgotten beyond this).
        camera_timeout_s: wall seconds without an accepted frame after which the camera counts as lost.
        status_interval_s: wall seconds between status log lines (0: never).
        recv_buffer_bytes: socket receive buffer asked of the OS.
        batch: datagrams read per loop iteration before timers are checked."""

    listen: Address = (LOCALHOST, 0)
    publish: tuple[Address, ...] = ()
    reply_to_robots: bool = True
    group: Address | None = None
    group_interface: str = LOCALHOST
    sender_rate: float = 2000.0
    sender_burst: float = 500.0
    max_senders: int = 1024
    camera_timeout_s: float = 2.0
    status_interval_s: float = 5.0
    recv_buffer_bytes: int = 4 << 20
    batch: int = 256

    def __post_init__(self) -> None:
        for name, option in (("sender_rate", "--rate"), ("sender_burst", "--burst"),
                             ("camera_timeout_s", "--camera-timeout")):
            if not getattr(self, name) > 0:
                raise ValueError(f"NodeConfig.{name} ({option}) must be > 0, got {getattr(self, name)}")
        if not self.sender_burst >= 1:  # (a sender needs one whole token a packet: below 1 nothing passes)
            raise ValueError(f"NodeConfig.sender_burst (--burst) must be >= 1 packet, got {self.sender_burst:g}")
        if not self.status_interval_s >= 0:
            raise ValueError(f"NodeConfig.status_interval_s (--status-interval) must be >= 0 (0: never), got "
                             f"{self.status_interval_s}")
        if self.max_senders < 1 or self.batch < 1:
            raise ValueError("NodeConfig.max_senders and NodeConfig.batch must be >= 1")
        if self.group is not None:
            check_group(self.group)


_Node = TypeVar("_Node", bound="NodeCore")


class NodeCore(abc.ABC):
    """What every transport of the node shares: the identifier, counters, rate limits, camera timer and status log.
    A transport reads messages, calls :meth:`accept` and :meth:`handle_message`, and implements ``poll`` and
    ``_publish``; ``serve(stop)`` loops until ``stop()`` is true."""

    def __init__(self, tracker: object, config: NodeConfig | None = None,
                 identifier_config: IdentifierConfig | None = None,
                 logger: logging.Logger | None = None) -> None:
        self.config = config or NodeConfig()
        self.identifier = TeamIdentifier(tracker, identifier_config)
        self.counters = NodeCounters()
        self.log = logger or logging.getLogger("lookalike.node")
        self._buckets: dict[Hashable, list[float]] = {}
        self._robot_addr: dict[int, Address] = {}
        self._last_frame_wall: float | None = None
        self._camera: Hashable | None = None  # the sender of the last accepted frame
        self._next_status = time.monotonic() + self.config.status_interval_s
        self._cpu_received: float | None = None  # thread CPU time when the message being handled was read

    def serve(self, stop: Callable[[], bool], tick_s: float = 0.05) -> None:
        """Serve until ``stop()`` is true (checked every ``tick_s`` s), with ``gc.freeze`` and one BLAS thread."""
        gc.collect()
        gc.freeze()
        try:
            with one_blas_thread():
                while not stop():
                    self.poll(tick_s)
        finally:
            gc.unfreeze()

    @abc.abstractmethod
    def poll(self, timeout_s: float) -> int:
        """Wait up to ``timeout_s`` for messages, handle them; return how many."""

    def __enter__(self: _Node) -> _Node:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def close(self) -> None:
        """Log the final counters."""
        log_event(self.log, "stopped", counters=self.counters.snapshot())

    @abc.abstractmethod
    def _publish(self, team: TeamState) -> None:
        """Send ``team`` to the robots (the transport's job)."""

    def accept(self, sender: Hashable, t_received: float) -> bool:
        """Count one received message of ``sender``; False when the sender is rate-limited (counted)."""
        self.counters.add("received")
        if not self._allow(sender, t_received):
            self.counters.add("rate_limited")
            return False
        return True

    def handle_message(self, message: HeadingReport | DetectionsMessage, sender: Hashable,
                       t_received: float) -> None:
        """Process one decoded report or frame of ``sender`` read at ``t_received`` (``time.perf_counter`` s); one
        outside the wire's bounds (made in Python, or from ROS 2) is counted under ``rejected`` and dropped."""
        try:
            self._handle_message(message, sender, t_received)
        except MessageError as exc:
            self.counters.reject(exc.reason)
            log_event(self.log, "rejected", logging.DEBUG, sender=_show(sender), reason=exc.reason, detail=exc.detail)

    def _handle_message(self, message: HeadingReport | DetectionsMessage, sender: Hashable,
                        t_received: float) -> None:
        if isinstance(message, HeadingReport):
            dropped = self.identifier.queue_dropped
            outcome = self.identifier.add_report(message)
            self.counters.add(outcome)
            if self.identifier.queue_dropped > dropped:
                self.counters.add("queue_dropped", self.identifier.queue_dropped - dropped)
            if outcome == "reports":
                if isinstance(sender, tuple):
                    self._robot_addr[message.robot] = sender
            else:
                log_event(self.log, outcome, logging.DEBUG, sender=_show(sender), robot=message.robot,
                          seq=message.seq)
        else:
            self._frame(message, sender, t_received)

    def _frame(self, message: DetectionsMessage, addr: Hashable, t_received: float) -> None:
        identifier = self.identifier
        if self._camera is not None and addr != self._camera and not identifier.camera_lost:
            self.counters.add("other_camera")
            log_event(self.log, "other_camera", logging.DEBUG, sender=_show(addr), frame=message.frame)
            return
        restarts, robot_resets = identifier.restarts, identifier.robot_resets
        try:
            outcome, team = identifier.add_frame(message)
        except MessageError:
            raise  # (a message outside the bounds: rejected, the camera unchanged)
        except Exception as exc:  # noqa: BLE001 (a tracker bug must not take the node down)
            self._camera, self._last_frame_wall = addr, time.monotonic()
            self.counters.add("tracker_errors")
            log_event(self.log, "tracker_error", logging.ERROR, frame=message.frame, error=repr(exc))
            return
        if outcome == "frames":  # (only an accepted frame shows the camera is alive)
            self._camera, self._last_frame_wall = addr, time.monotonic()
        if identifier.restarts > restarts:
            self.counters.add("camera_restarts")
            log_event(self.log, "camera_restart", frame=message.frame, time=message.time)
        if identifier.robot_resets > robot_resets:
            self.counters.add("robot_resets", identifier.robot_resets - robot_resets)
            log_event(self.log, "robot_reset", frame=message.frame, time=message.time)
        self.counters.add(outcome)
        if team is None:
            log_event(self.log, outcome, logging.DEBUG, sender=_show(addr), frame=message.frame)
            return
        self._publish(team)
        self.counters.latency_s.append(time.perf_counter() - t_received)
        cpu_sent = time.thread_time()
        try:  # (after the send: the next frame's prediction, off that frame's path)
            self.identifier.prepare()
        except Exception as exc:  # noqa: BLE001 (a tracker bug must not take the node down)
            self.counters.add("tracker_errors")
            log_event(self.log, "tracker_error", logging.ERROR, frame=message.frame, error=repr(exc))
        if self._cpu_received is not None:
            self.counters.cpu_s.append(cpu_sent - self._cpu_received)
            self.counters.cpu_with_prepare_s.append(time.thread_time() - self._cpu_received)

    def _allow(self, addr: Hashable, now: float) -> bool:
        """Token bucket per sender address."""
        bucket = self._buckets.get(addr)
        if bucket is None:
            if len(self._buckets) >= self.config.max_senders:
                self._buckets.pop(next(iter(self._buckets)))
            bucket = self._buckets[addr] = [self.config.sender_burst, now]
        tokens = min(self.config.sender_burst, bucket[0] + (now - bucket[1]) * self.config.sender_rate)
        bucket[1] = now
        if tokens < 1.0:
            bucket[0] = tokens
            return False
        bucket[0] = tokens - 1.0
        return True

    def _timers(self) -> None:
        now = time.monotonic()
        last = self._last_frame_wall
        if last is not None and not self.identifier.camera_lost and now - last > self.config.camera_timeout_s:
            self.identifier.camera_lost = True
            self.counters.add("camera_lost")
            log_event(self.log, "camera_lost", logging.WARNING, silent_s=round(now - last, 3),
                      last_frame=self.identifier.last_frame)
        if self.config.status_interval_s > 0 and now >= self._next_status:
            self._next_status = now + self.config.status_interval_s
            log_event(self.log, "status", line=self.counters.status_line(), counters=self.counters.snapshot())


class NodeServer(NodeCore):
    """The running UDP node. Use as a context manager; ``serve(stop)`` loops until ``stop()`` is true."""

    def __init__(self, tracker: object, config: NodeConfig | None = None,
                 identifier_config: IdentifierConfig | None = None,
                 logger: logging.Logger | None = None) -> None:
        super().__init__(tracker, config, identifier_config, logger)
        self._targets = tuple(map(resolve_destination, self.config.publish))  # (ValueError: no destination)
        self.sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        try:
            self.sock.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, self.config.recv_buffer_bytes)
            self.sock.bind(self.config.listen)
            if self.config.group is not None:
                self.sock.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_IF,
                                     socket.inet_aton(self.config.group_interface))
                self.sock.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_LOOP, 1)
        except OSError:
            self.sock.close()
            raise
        self.sock.setblocking(False)
        self.selector = selectors.DefaultSelector()
        self.selector.register(self.sock, selectors.EVENT_READ)
        _preload()  # (before the address is announced: the first frame does not wait for imports)
        log_event(self.log, "listening", address=list(self.address))

    @property
    def address(self) -> Address:
        """The bound ``(host, port)``."""
        return self.sock.getsockname()

    def close(self) -> None:
        """Log the final counters and close the socket."""
        if self.sock.fileno() >= 0:
            log_event(self.log, "stopped", counters=self.counters.snapshot())
            self.selector.close()
            self.sock.close()

    def poll(self, timeout_s: float) -> int:
        """Wait up to ``timeout_s`` for datagrams, handle up to ``batch`` of them; return how many."""
        handled = 0
        if self.selector.select(timeout_s):
            while handled < self.config.batch:
                try:
                    data, addr = self.sock.recvfrom(65_535)
                except (BlockingIOError, InterruptedError):
                    break
                except OSError as exc:  # e.g. an ICMP error reported on the socket
                    log_event(self.log, "socket_error", logging.WARNING, error=str(exc))
                    break
                handled += 1
                self._cpu_received = time.thread_time()
                try:
                    self.handle(data, addr, time.perf_counter())
                except Exception as exc:  # noqa: BLE001 (a bug of the node must not stop the loop)
                    self.counters.add("handler_errors")
                    log_event(self.log, "handler_error", logging.ERROR, sender=list(addr), error=repr(exc))
        self._timers()
        return handled

    def handle(self, data: bytes, addr: Address, t_received: float) -> None:
        """Process one datagram read at ``t_received`` (``time.perf_counter`` seconds)."""
        if not self.accept(addr, t_received):
            return
        try:
            message = decode(data)
        except MessageError as exc:
            self.counters.reject(exc.reason)
            log_event(self.log, "rejected", logging.DEBUG, sender=list(addr), reason=exc.reason, detail=exc.detail)
            return
        if isinstance(message, (HeadingReport, DetectionsMessage)):
            self.handle_message(message, addr, t_received)
        elif isinstance(message, StatusRequest):
            self.counters.add("status_requests")
            self._send(encode(Status(counters=self.counters.snapshot())), [addr], counted=False)
        else:  # a team or status message sent to the node
            self.counters.reject(UNEXPECTED)

    def _publish(self, team: TeamState) -> None:
        try:
            data = encode(team)
        except ValueError as exc:
            log_event(self.log, "encode_error", logging.ERROR, frame=team.frame, error=str(exc))
            return
        targets = list(self._targets)
        if self.config.group is not None:
            targets.append(self.config.group)
        elif self.config.reply_to_robots:
            targets += [a for a in self._robot_addr.values() if a not in targets]
        self._send(data, targets)

    def _send(self, data: bytes, targets: list[Address], counted: bool = True) -> None:
        """Send ``data`` to each target; team states count as ``published``."""
        for target in targets:
            try:
                self.sock.sendto(data, target)
                if counted:
                    self.counters.add("published")
            except OSError as exc:
                self.counters.add("send_errors")
                log_event(self.log, "send_error", logging.WARNING, target=list(target), error=str(exc))


def _show(sender: Hashable) -> object:
    """A sender as logged: an address as ``[host, port]``, anything else as its text."""
    return list(sender) if isinstance(sender, tuple) else str(sender)


def dds_node(tracker: object, domain_id: int, config: NodeConfig | None = None,
             identifier_config: IdentifierConfig | None = None, logger: logging.Logger | None = None) -> NodeCore:
    """The node on DDS with ROS 2's names (:class:`lookalike.node.dds.DdsNode`) in domain ``domain_id``; raises
    :class:`lookalike._optional.MissingExtra` without the ``ros`` extra."""
    from lookalike.node.dds import DdsConfig, DdsNode

    return DdsNode(tracker, DdsConfig(domain_id=domain_id), config, identifier_config, logger)
