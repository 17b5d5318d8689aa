"""A small UDP endpoint for talking to the node: what robots, cameras and tests use."""

from __future__ import annotations

import selectors
import socket
import time

from lookalike.node.messages import Message, MessageError, decode, encode

Address = tuple[str, int]


def resolve_destination(address: Address) -> Address:
    """``address`` as the numeric IPv4 ``(host, port)`` to send to, looked up once; raises ``ValueError`` naming it for
    port 0 or a host that does not resolve (sent to as given, a host name would be looked up for every datagram)."""
    host, port = address
    if not 0 < port <= 65535:
        raise ValueError(f"address {host}:{port}: a destination needs a port in 1..65535")
    try:
        found = socket.getaddrinfo(host, port, socket.AF_INET, socket.SOCK_DGRAM)
    except (OSError, UnicodeError) as exc:
        raise ValueError(f"address {host}:{port}: the host does not resolve to an IPv4 address ({exc})") from None
    return str(found[0][4][0]), port


class Endpoint:
    """A UDP socket bound to ``bind`` (default: an ephemeral loopback port) that sends messages to ``peer`` and
    receives decoded ones; a context manager. With ``group`` (IPv4 multicast ``(address, port)`` joined on
    ``interface``) a second socket receives the node's batched team states. A ``peer`` that is no destination
    (:func:`resolve_destination`) raises ``ValueError``."""

    def __init__(self, peer: Address, bind: Address = ("127.0.0.1", 0), group: Address | None = None,
                 interface: str = "127.0.0.1") -> None:
        self.peer = resolve_destination(peer)
        self.sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        self.group_sock: socket.socket | None = None
        self.selector = selectors.DefaultSelector()
        try:
            self.sock.bind(bind)
            self.selector.register(self.sock, selectors.EVENT_READ)
            if group is not None:
                self.group_sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
                self.group_sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
                self.group_sock.bind(("", group[1]))
                self.group_sock.setsockopt(socket.IPPROTO_IP, socket.IP_ADD_MEMBERSHIP,
                                           socket.inet_aton(group[0]) + socket.inet_aton(interface))
                self.selector.register(self.group_sock, selectors.EVENT_READ)
        except OSError:
            self.close()
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
        """Close the sockets."""
        self.selector.close()
        self.sock.close()
        if self.group_sock is not None:
            self.group_sock.close()

    def send(self, message: Message) -> None:
        """Send one message to the peer."""
        self.send_bytes(encode(message))

    def send_bytes(self, data: bytes) -> None:
        """Send raw bytes to the peer (for fault injection)."""
        self.sock.sendto(data, self.peer)

    def receive(self, timeout_s: float) -> Message | None:
        """The next valid message within ``timeout_s`` seconds, or None; invalid ones counted in ``rejected``."""
        deadline = time.monotonic() + timeout_s
        while True:
            remaining = deadline - time.monotonic()
            if remaining <= 0:
                return None
            for key, _ in self.selector.select(remaining):
                try:
                    data, _ = key.fileobj.recvfrom(65_535, socket.MSG_DONTWAIT)  # type: ignore[union-attr]
                except OSError:  # (nothing to read after all, or an ICMP error)
                    continue
                try:
                    return decode(data)
                except MessageError:
                    self.rejected += 1

    def drain(self) -> list[Message]:
        """Every message already waiting, without blocking."""
        return list(iter(lambda: self.receive(1e-4), None))
