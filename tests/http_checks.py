"""HTTP checks that the labelling and proofreading pages' servers share: raw JSON posts, requests too broken to route,
and a burst of queued connections."""

from __future__ import annotations

import socket
import threading
from socketserver import BaseServer


def post_bytes(path: str, body: bytes) -> bytes:
    """A raw HTTP/1.1 JSON POST of ``body`` to ``path`` on loopback, closing the connection after the reply."""
    return (b"POST %s HTTP/1.1\r\nHost: 127.0.0.1\r\nContent-Type: application/json\r\n"
            b"Content-Length: %d\r\nConnection: close\r\n\r\n%s" % (path.encode(), len(body), body))


def assert_survives_malformed(port: int, post_path: str) -> None:
    """Requests too broken to route, one per connection: each gets an HTTP/1.x status line, http.server's HTML error
    page for requests too broken to say, or nothing."""
    head = b"POST %s HTTP/1.1\r\nHost: 127.0.0.1\r\nContent-Type: application/json\r\n" % post_path.encode()
    for raw in (b"GARBAGE\r\n\r\n", b"GET\r\n\r\n", b"\x00\xff\xfe nonsense\r\n\r\n",
                head + b"Content-Length: 999999999\r\n\r\n{}", head + b"Content-Length: abc\r\n\r\n",
                b"GET /api/meta HTTP/1.1\r\n" + b"X: " + b"a" * 70000 + b"\r\n\r\n"):
        with socket.create_connection(("127.0.0.1", port), timeout=10) as s:
            s.sendall(raw)
            s.shutdown(socket.SHUT_WR)
            reply = s.recv(200)
        assert reply == b"" or reply.startswith(b"HTTP/1.") or b"Error code: 400" in reply, (raw[:30], reply)


def burst_replies(server: BaseServer, request: bytes, n: int = 100) -> list[bytes]:
    """Open ``n`` connections to ``server`` before it serves (they wait in the listen queue), then serve it, send
    ``request`` on each and return the first bytes of each reply. The server is shut down after (not closed)."""
    address = server.server_address
    assert isinstance(address, tuple)
    pending = [socket.create_connection(("127.0.0.1", address[1]), timeout=10) for _ in range(n)]
    thread = threading.Thread(target=server.serve_forever, daemon=True)
    thread.start()
    try:
        for s in pending:
            s.sendall(request)
        return [s.recv(64) for s in pending]
    finally:
        for s in pending:
            s.close()
        server.shutdown()
        thread.join(5)
