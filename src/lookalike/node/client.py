"""A small UDP endpoint for talking to the node: what robots, cameras and tests use."""

from __future__ import annotations

import socket
import time

from lookalike.node.messages import Message, MessageError, decode, encode

Address = tuple[str, int]


class Endpoint:
    """A UDP socket bound to ``bind`` (default: an ephemeral loopback port) that sends messages
    to ``peer`` and receives decoded messages. Use as a context manager."""

    def __init__(self, peer: Address, bind: Address = ("127.0.0.1", 0)) -> None:
        self.peer = peer
        self.sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        try:
            self.sock.bind(bind)
        except OSError:
            self.sock.close()
            raise
        self.rejected = 0

    @property
    def address(self) -> Address:
        """The bound ``(host, port)``."""
        return self.sock.getsockname()

    def __enter__(self) -> Endpoint:  # noqa: PYI034
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def close(self) -> None:
        """Close the socket."""
        self.sock.close()

    def send(self, message: Message) -> None:
        """Send one message to the peer."""
        self.send_bytes(encode(message))

    def send_bytes(self, data: bytes) -> None:
        """Send raw bytes to the peer (for fault injection)."""
        self.sock.sendto(data, self.peer)

    def receive(self, timeout_s: float) -> Message | None:
        """The next valid message within ``timeout_s`` seconds, or None; invalid datagrams are
        counted in ``rejected`` and skipped."""
        deadline = time.monotonic() + timeout_s
        while True:
            remaining = deadline - time.monotonic()
            if remaining <= 0:
                return None
            self.sock.settimeout(remaining)
            try:
                data, _ = self.sock.recvfrom(65_535)
            except TimeoutError:
                return None
            except OSError:
                continue
            try:
                return decode(data)
            except MessageError:
                self.rejected += 1

    def drain(self) -> list[Message]:
        """Every message already waiting, without blocking."""
        out = []
        while (msg := self.receive(1e-4)) is not None:
            out.append(msg)
        return out
