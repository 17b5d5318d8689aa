"""The labelling page's protection tests, on the proofreading page: loopback by default, malformed requests answered
and survived, a burst of connections queued, saved files that follow the umask, and arbitrary bodies to every write
that never give a 500 or leave a partial log (hypothesis)."""

from __future__ import annotations

import json
import os
import socket
import stat

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from lookalike.proofread import Correction
from lookalike.viz.label.server import LISTEN_BACKLOG
from tests.http_checks import assert_survives_malformed, burst_replies, post_bytes
from tests.test_label_property import json_values
from tests.test_proofread_page import SWAP, Served, open_page

pytest.importorskip("cv2")
from lookalike.viz.label.proofread import make_proofread_server  # noqa: E402

SWAP_BODY = {"kind": "swap", "track": 1, "other": 2, "frame": SWAP}


def test_binds_loopback_by_default(tmp_path):
    server = make_proofread_server(open_page(tmp_path), port=0)
    try:
        assert server.server_address[0] == "127.0.0.1"
    finally:
        server.server_close()


def test_survives_malformed_requests(tmp_path):
    with Served(open_page(tmp_path)) as s:
        assert_survives_malformed(s.port, "/api/correct")
        for path, body in [("/api/correct", {"kind": "rename", "track": 1}), ("/api/correct", {"track": 1}),
                           ("/api/correct", {"kind": "swap", "track": 1, "other": 2, "frame": 99}),
                           ("/api/correct", {"kind": "delete", "track": "one"}), ("/api/undo", {}),
                           ("/api/nothing", {})]:
            status, r = s.request("POST", path, body)
            assert 400 <= status < 500 and "error" in r, (path, body, status, r)
        for path in ("/api/frame?k=x", "/api/frame?k=0", "/api/tracks?start=0", "/api/tracks?count=100000",
                     "/api/nowhere"):
            status, r = s.request("GET", path)
            assert 400 <= status < 500 and "error" in r, (path, status, r)
        assert s.request("GET", "/api/meta", headers={"Host": "evil.example:80"})[0] == 403
        assert s.request("GET", "/api/state")[0] == 200  # still serving


def test_listen_backlog_takes_a_burst_of_corrections(tmp_path):
    page = open_page(tmp_path)
    server = make_proofread_server(page, port=0)
    try:
        assert server.request_queue_size == LISTEN_BACKLOG >= 128
        replies = burst_replies(server, post_bytes("/api/correct", json.dumps(SWAP_BODY).encode()))
        assert all(r.startswith(b"HTTP/1.0 200") for r in replies), {r[:20] for r in replies}
        assert page.version == 100 and len(page.session.corrections) == 100
    finally:
        server.server_close()


@pytest.mark.parametrize("mask", [0o022, 0o077])
def test_saved_files_follow_the_umask(tmp_path, mask):
    old = os.umask(mask)
    try:
        page = open_page(tmp_path)
        page.correct(SWAP_BODY)
        page.export()
        for path in (page.log_path, page.export_path):
            assert stat.S_IMODE(path.stat().st_mode) == 0o666 & ~mask, path
    finally:
        os.umask(old)


@pytest.fixture(scope="module")
def served(tmp_path_factory):
    folder = tmp_path_factory.mktemp("proofread-prop")
    page = open_page(folder)
    with Served(page, body_timeout_s=2.0) as s:
        yield s, page


def _check_log(page) -> None:
    """The log is whole (header, then one correction per line, as many as the session holds); no temporary files."""
    if not page.log_path.exists():
        return
    lines = page.log_path.read_text().splitlines()
    assert "lookalike_proofread" in json.loads(lines[0])
    assert [Correction.from_json(line) for line in lines[1:]] == page.session.corrections
    assert not [p for p in page.log_path.parent.iterdir() if p.name.endswith(".tmp")]


correction_bodies = st.fixed_dictionaries(
    {}, optional={"kind": json_values | st.sampled_from(["swap", "merge", "split", "delete", "assign"]),
                  "track": json_values | st.integers(-1, 4), "other": json_values | st.integers(-1, 4),
                  "frame": json_values | st.integers(-1, 22), "extra": json_values})


def _encode(value) -> bytes:
    return json.dumps(value, allow_nan=True).encode()


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(path=st.sampled_from(["/api/correct", "/api/correct", "/api/correct", "/api/undo", "/api/export"]),
       body=st.one_of(st.binary(max_size=100), correction_bodies.map(_encode), json_values.map(_encode)))
def test_writes_never_fail_with_500(served, path, body):
    s, page = served
    conn = socket.create_connection(("127.0.0.1", s.port), timeout=10)
    with conn:
        conn.sendall(post_bytes(path, body))
        reply = b""
        while chunk := conn.recv(4096):
            reply += chunk
    status = int(reply.split(b" ", 2)[1])
    assert status in (200, 400), (path, body, reply[:300])
    payload = json.loads(reply.split(b"\r\n\r\n", 1)[1])
    assert ("error" in payload and "Traceback" not in payload["error"]) if status == 400 else "error" not in payload
    _check_log(page)
