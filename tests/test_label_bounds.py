"""Issue 19, labelling-page rows: a short request body, the listen backlog, the truth in
benchmark mode, and the label file's mode."""

from __future__ import annotations

import json
import os
import socket
import stat
import threading

import pytest

from lookalike.io.outputs import write_atomic
from lookalike.io.rules import user_mode
from lookalike.viz.label import make_server, open_label_app
from lookalike.viz.label.server import LISTEN_BACKLOG
from tests.http_checks import burst_replies, post_bytes
from tests.test_label_server import _json, _request, seq_path  # noqa: F401 (fixture)


def _serve(app, **kwargs):
    server = make_server(app, port=0, **kwargs)
    thread = threading.Thread(target=server.serve_forever, daemon=True)
    thread.start()
    return server, thread


def _stop(server, thread):
    server.shutdown()
    server.server_close()
    thread.join(5)


def test_short_body_times_out_without_holding_up_others(seq_path):  # noqa: F811
    """Row: a request sending fewer bytes than it declares hung a worker 30 s, then 500."""
    server, thread = _serve(open_label_app(seq_path), body_timeout_s=1.0)
    try:
        slow = socket.create_connection(("127.0.0.1", server.server_address[1]), timeout=20)
        slow.sendall(b"POST /api/label HTTP/1.1\r\nHost: 127.0.0.1\r\nContent-Type: application/json\r\n"
                     b"Content-Length: 100\r\n\r\n{\"frame\": 0")
        # Meanwhile other requests are answered (each connection has its own thread).
        for _ in range(3):
            assert _json(server, "GET", "/api/meta")[0] == 200
            assert _json(server, "POST", "/api/label", {"frame": 0, "detection": 0, "label": 0})[0] == 200
        reply = b""
        while chunk := slow.recv(4096):  # the headers and the body may come in separate packets
            reply += chunk
        slow.close()
        assert reply.startswith(b"HTTP/1.0 408") or reply.startswith(b"HTTP/1.1 408"), reply[:80]
        assert b"not received within 1 s" in reply
        assert _json(server, "GET", "/api/meta")[0] == 200
    finally:
        _stop(server, thread)


def test_listen_backlog_takes_a_burst_of_connections(seq_path):  # noqa: F811
    """Row: backlog 5, so 4 of 417 concurrent saves were reset."""
    server = make_server(open_label_app(seq_path), port=0)
    try:
        assert server.request_queue_size == LISTEN_BACKLOG >= 128
        # Not serving yet: 100 connections wait in the kernel's queue instead of being refused.
        body = json.dumps({"frame": 0, "detection": 0, "label": 0}).encode()
        replies = burst_replies(server, post_bytes("/api/label", body))
        assert all(r.startswith(b"HTTP/1.0 200") for r in replies), {r[:20] for r in replies}
    finally:
        server.server_close()


def test_benchmark_mode_serves_no_truth(seq_path):  # noqa: F811
    """Row: in --benchmark mode the hidden truth was served at /files/<sequence>.jsonl."""
    seq_path.with_name("m3n2-000003.labelled.jsonl").write_text(seq_path.read_text())
    (seq_path.parent / "gt.txt").write_text("1,1,0,0,1,1,1,-1,-1,-1\n")
    (seq_path.parent / "m3n2-000003_frames" / "notes.txt").write_text("truth")
    server, thread = _serve(open_label_app(seq_path, benchmark=True))
    try:
        for name in (seq_path.name, "m3n2-000003.labelled.jsonl", "gt.txt", "m3n2-000003.labels.json",
                     "m3n2-000003_frames/notes.txt", "m3n2-000003_frames/../m3n2-000003.jsonl"):
            status, data = _request(server, "GET", f"/files/{name}")
            assert status == 403, (name, status)
            assert b"true_position" not in data and b"label" not in data
        assert _request(server, "GET", "/files/m3n2-000003_frames/000001.png") == (200, b"\x89PNG fake")
    finally:
        _stop(server, thread)
    server, thread = _serve(open_label_app(seq_path))  # outside benchmark mode the folder is served
    try:
        assert _request(server, "GET", f"/files/{seq_path.name}")[0] == 200
    finally:
        _stop(server, thread)


@pytest.mark.parametrize("mask", [0o022, 0o002, 0o077])
def test_label_files_follow_the_umask(tmp_path, seq_path, mask):  # noqa: F811
    """Row: label files were created with mode 0600 instead of the user's umask."""
    old = os.umask(mask)
    try:
        assert user_mode() == 0o666 & ~mask
        write_atomic(tmp_path / "x.json", "{}")
        assert stat.S_IMODE((tmp_path / "x.json").stat().st_mode) == 0o666 & ~mask
        app = open_label_app(seq_path, fresh=True)
        app.store.set_label(0, 0, 0)
        assert stat.S_IMODE(app.store.path.stat().st_mode) == 0o666 & ~mask
    finally:
        os.umask(old)
