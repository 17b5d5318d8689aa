"""The labelling server: loopback binding, no files outside the sequence folder, malformed
requests answered and survived, the JSON API, and the ``lookalike label`` command."""

from __future__ import annotations

import http.client
import json
import threading

import pytest

from lookalike.io.robot_sequences import write_robot_sequence
from lookalike.sim import preset, simulate_robots
from lookalike.viz.label import make_server, open_label_app
from tests.http_checks import assert_survives_malformed


@pytest.fixture()
def seq_path(tmp_path):
    folder = tmp_path / "seqs"
    path = write_robot_sequence(folder / "m3n2-000003.jsonl", simulate_robots(preset("m3n2"), 30, 3))
    (folder / "m3n2-000003_frames").mkdir()
    (folder / "m3n2-000003_frames" / "000001.png").write_bytes(b"\x89PNG fake")
    (tmp_path / "secret.txt").write_text("not for the page")
    return path


def _serve(app):
    server = make_server(app, port=0)
    thread = threading.Thread(target=server.serve_forever, daemon=True)
    thread.start()
    return server, thread


@pytest.fixture()
def served(seq_path):
    server, thread = _serve(open_label_app(seq_path))
    yield server
    server.shutdown()
    server.server_close()
    thread.join(5)


def _request(server, method, path, body=None, headers=None):
    conn = http.client.HTTPConnection("127.0.0.1", server.server_address[1], timeout=10)
    hdrs = {"Content-Type": "application/json"} if body is not None else {}
    hdrs.update(headers or {})
    conn.request(method, path, body=body, headers=hdrs)
    r = conn.getresponse()
    data = r.read()
    conn.close()
    return r.status, data


def _json(server, method, path, payload=None):
    status, data = _request(server, method, path, None if payload is None else json.dumps(payload))
    return status, json.loads(data)


def test_binds_loopback_by_default(served):
    assert served.server_address[0] == "127.0.0.1"


def test_serves_the_page_and_the_sequence(served):
    status, page = _request(served, "GET", "/")
    assert status == 200 and b"static/app.js" in page
    assert _request(served, "GET", "/static/app.js")[0] == 200
    status, meta = _json(served, "GET", "/api/meta")
    assert status == 200 and meta["n_frames"] == 30 and meta["n_agents"] == 2 and meta["has_truth"]
    assert meta["image_pattern"] == "files/m3n2-000003_frames/{frame:06d}.png"
    assert _request(served, "GET", "/files/m3n2-000003_frames/000001.png") == (200, b"\x89PNG fake")
    status, frames = _json(served, "GET", "/api/frames?start=28&count=10")
    assert status == 200 and [f["frame"] for f in frames["frames"]] == [28, 29]
    assert all(len(f["truth"]) == len(f["detections"]) for f in frames["frames"])


@pytest.mark.parametrize("path", [
    "/files/../secret.txt", "/files/%2e%2e/secret.txt", "/files/..%2fsecret.txt", "/files//etc/passwd",
    "/files/%2fetc%2fpasswd", "/files/m3n2-000003_frames/../../secret.txt", "/files/",
    "/static/../store.py", "/static/%2e%2e%2fstore.py",
])
def test_refuses_paths_outside_the_sequence_folder(served, path):
    status, data = _request(served, "GET", path)
    assert status in (403, 404), (path, status)
    assert b"not for the page" not in data and b"root:" not in data


def test_refuses_a_symlink_out_of_the_folder(served, seq_path):
    (seq_path.parent / "link.txt").symlink_to(seq_path.parent.parent / "secret.txt")
    assert _request(served, "GET", "/files/link.txt")[0] == 403


def test_survives_malformed_requests(served):
    assert_survives_malformed(served.server_address[1], "/api/label")
    bad = [("POST", "/api/label", "{not json"), ("POST", "/api/label", "[1, 2]"),
           ("POST", "/api/label", json.dumps({"frame": 0})),
           ("POST", "/api/label", json.dumps({"frame": "x", "detection": 0, "label": 0})),
           ("POST", "/api/label", json.dumps({"frame": 10**9, "detection": 0, "label": 0})),
           ("POST", "/api/label", json.dumps({"frame": 0, "detection": 0, "label": 7})),
           ("POST", "/api/nothing", "{}"), ("GET", "/api/frames?start=x", None),
           ("GET", "/api/frames?count=100000", None), ("GET", "/api/nowhere", None),
           ("POST", "/api/benchmark/start", "{}")]
    for method, path, body in bad:
        status, data = _request(served, method, path, body)
        assert 400 <= status < 500, (method, path, body, status)
        assert "error" in json.loads(data)
    status, _ = _request(served, "POST", "/api/label", "frame=0", {"Content-Type": "text/plain"})
    assert status == 415
    assert _request(served, "GET", "/api/meta", headers={"Host": "evil.example:80"})[0] == 403
    assert _json(served, "GET", "/api/meta")[0] == 200  # still serving


def test_label_api_saves_and_scores(served, seq_path):
    _, frames = _json(served, "GET", "/api/frames?start=0&count=30")
    truth = [f["truth"] for f in frames["frames"]]
    for k, t in enumerate(truth):
        for j, lab in enumerate(t):
            body = {"frame": k, "detection": j, "label": lab}
            assert _json(served, "POST", "/api/label", body) == (200, {"ok": True})
    status, score = _json(served, "GET", "/api/score")
    assert status == 200 and score["success_rate"] == 1.0 and score["unset"] == 0
    saved = json.loads(seq_path.with_name("m3n2-000003.labels.json").read_text())
    assert saved["labels"] == truth
    status, exported = _json(served, "POST", "/api/export", {})
    assert status == 200 and (seq_path.parent / exported["truth"]).is_file()
    assert (seq_path.parent / exported["mot"]).is_file()


def test_benchmark_mode_hides_truth_until_finished(seq_path):
    server, thread = _serve(open_label_app(seq_path, benchmark=True))
    try:
        _, frames = _json(server, "GET", "/api/frames?start=0&count=5")
        assert all("truth" not in f for f in frames["frames"])
        assert _json(server, "GET", "/api/meta")[1]["has_truth"] is False
        assert _request(server, "GET", "/api/score")[0] == 403
        assert _json(server, "POST", "/api/benchmark/finish", {})[0] == 400
        status, started = _json(server, "POST", "/api/benchmark/start", {})
        assert status == 200 and started["benchmark"]["finished_at"] is None
        k = next(f["frame"] for f in frames["frames"] if f["detections"])
        _json(server, "POST", "/api/label", {"frame": k, "detection": 0, "label": 0})
        status, done = _json(server, "POST", "/api/benchmark/finish", {})
        assert status == 200 and done["benchmark"]["duration_s"] >= 0
        assert done["benchmark"]["frames_scored"] == k + 1
        assert _json(server, "GET", "/api/score")[0] == 200
        assert _json(server, "POST", "/api/label", {"frame": k, "detection": 0, "label": 1})[0] == 400
    finally:
        server.shutdown()
        server.server_close()
        thread.join(5)


def test_cli_tracker_labels_and_export(seq_path):
    from typer.testing import CliRunner

    from lookalike.cli import app

    r = CliRunner().invoke(app, ["label", str(seq_path), "--tracks", "kalman_ha", "--export"])
    assert r.exit_code == 0, r.output
    saved = json.loads(seq_path.with_name("m3n2-000003.labels.json").read_text())
    assert saved["source"] == "tracker kalman_ha"
    assert any(v >= 0 for row in saved["labels"] for v in row)
    assert seq_path.with_name("m3n2-000003.labelled.jsonl").is_file()
    mot = seq_path.with_name("m3n2-000003.labels.mot.txt")
    r = CliRunner().invoke(app, ["label", str(seq_path), "--tracks", str(mot), "--export"])
    assert r.exit_code == 0 and "--tracks ignored" in r.output
    r = CliRunner().invoke(app, ["label", str(seq_path), "--tracks", str(mot), "--fresh", "--export"])
    assert r.exit_code == 0, r.output
    again = json.loads(seq_path.with_name("m3n2-000003.labels.json").read_text())
    assert again["source"] == "file m3n2-000003.labels.mot.txt"
    # MOT keeps the agents' detections; the false positives come back as -1
    def clipped(labels):
        return [[max(v, -1) for v in row] for row in labels]

    assert clipped(again["labels"]) == clipped(saved["labels"])
    r = CliRunner().invoke(app, ["label", str(seq_path), "--tracks", "no-such-tracker", "--export"])
    assert r.exit_code == 2 and "neither a file nor a tracker" in r.output
    r = CliRunner().invoke(app, ["label", str(seq_path), "--benchmark", "--tracks", "kalman_ha"])
    assert r.exit_code == 2
