"""The proofreading page's server: the JSON API over a session on a small video, the labelling server's protections
plus a refused cross-origin write, the log saved after each action and replayed, and ``lookalike proofread``."""

from __future__ import annotations

import http.client
import json
import socket
import threading
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from lookalike.cli import app
from lookalike.proofread import Correction, Session

cv2 = pytest.importorskip("cv2")
from lookalike.viz.label.proofread import ProofreadApp, make_proofread_server  # noqa: E402

FRAMES, SWAP = 20, 10
LANES = {1: 30, 2: 90}  # id -> lane (centre y, px)


def two_discs(folder: Path, scale: int = 1) -> tuple[Path, Path]:
    """A 160x120 video (times ``scale``) of two discs on lanes y = 30 and 90 px (times ``scale``), frames 1-20, and
    tracks whose ids swap at frame 10."""
    video, tracks = folder / "two.avi", folder / "two.txt"
    writer = cv2.VideoWriter(str(video), cv2.VideoWriter_fourcc(*"MJPG"), 10, (160 * scale, 120 * scale))
    rows = []
    for k in range(1, FRAMES + 1):
        img = np.full((120 * scale, 160 * scale, 3), 215, np.uint8)
        for tid, y in LANES.items():
            x, y, r = (10 + 6 * k) * scale, y * scale, 8 * scale
            cv2.circle(img, (x, y), r, (40, 40, 40), -1)
            rows.append([k, tid if k < SWAP else 3 - tid, x - r - 1, y - r - 1, 2 * r + 2, 2 * r + 2, 1, -1, -1, -1])
        writer.write(img)
    writer.release()
    np.savetxt(tracks, np.array(rows), fmt="%g", delimiter=",")
    return video, tracks


def lane_ids(rows: list[list[float]], frame: int) -> dict[int, int]:
    """Lane (centre y) -> id in ``frame`` of ``[frame, id, x, y, w, h]`` rows."""
    return {int(r[3] + r[5] / 2): int(r[1]) for r in rows if r[0] == frame}


class Served:
    """A page server on a free loopback port, in a thread."""

    def __init__(self, page: ProofreadApp, body_timeout_s: float = 5.0) -> None:
        self.server = make_proofread_server(page, port=0, body_timeout_s=body_timeout_s)
        self.thread = threading.Thread(target=self.server.serve_forever, daemon=True)
        self.port = self.server.server_address[1]
        self.url = f"http://127.0.0.1:{self.port}/"

    def __enter__(self) -> Served:
        self.thread.start()
        return self

    def __exit__(self, *exc: object) -> None:
        self.server.shutdown()
        self.server.server_close()
        self.thread.join(5)

    def request(self, method: str, path: str, body: object = None, headers: dict[str, str] | None = None):
        conn = http.client.HTTPConnection("127.0.0.1", self.port, timeout=10)
        hdrs = {"Content-Type": "application/json"} if body is not None else {}
        hdrs.update(headers or {})
        conn.request(method, path, body=None if body is None else json.dumps(body), headers=hdrs)
        r = conn.getresponse()
        data = r.read()
        conn.close()
        return r.status, (json.loads(data) if r.getheader("Content-Type") == "application/json" else data)


def open_page(folder: Path, scale: int = 1, **kw) -> ProofreadApp:
    video, tracks = two_discs(folder, scale)
    return ProofreadApp(Session(tracks, frame_rate=10, **kw), video, folder / "two.corrections.jsonl",
                        folder / "two.proofread.txt", Correction.from_json)


def test_correct_undo_and_export_through_the_api(tmp_path):
    page = open_page(tmp_path)
    with Served(page) as s:
        status, meta = s.request("GET", "/api/meta")
        assert status == 200 and (meta["width"], meta["height"], meta["n_frames"]) == (160, 120, FRAMES)
        assert not meta["propagates"]
        status, jpeg = s.request("GET", "/api/frame?k=3")
        assert status == 200 and jpeg[:2] == b"\xff\xd8"
        assert s.request("GET", "/api/frame?k=99")[0] == 404
        assert s.request("GET", "/")[0] == 200 and s.request("GET", "/static/proofread.js")[0] == 200
        status, r = s.request("POST", "/api/correct", {"kind": "swap", "track": 2, "other": 1, "frame": SWAP})
        assert status == 200 and r["version"] == 1 and "frames 10-20" in r["message"]
        rows = s.request("GET", "/api/tracks?start=1&count=50")[1]["rows"]
        assert all(lane_ids(rows, f) == {30: 1, 90: 2} for f in range(1, FRAMES + 1))
        assert Correction.from_json((tmp_path / "two.corrections.jsonl").read_text().splitlines()[1]) == \
            Correction("swap", 2, 1, SWAP)  # saved at once
        status, r = s.request("POST", "/api/correct", {"kind": "delete", "track": 7})
        assert status == 400 and "unknown track id 7" in r["error"]
        status, r = s.request("POST", "/api/correct", {"kind": "swap", "track": 2})
        assert status == 400 and "needs track, other, frame" in r["error"]
        assert s.request("POST", "/api/undo", {})[1]["version"] == 2
        rows = s.request("GET", "/api/tracks?start=1&count=50")[1]["rows"]
        assert lane_ids(rows, 12) == {30: 2, 90: 1}
        s.request("POST", "/api/correct", {"kind": "assign", "track": 1, "other": 5, "frame": 15})
        status, state = s.request("GET", "/api/state")
        assert state["spans"] == {"1": [[1, 14]], "2": [[1, 20]], "5": [[15, 20]]}
        assert [c["kind"] for c in state["corrections"]] == ["assign"]
        status, r = s.request("POST", "/api/export", {})
        assert status == 200 and r["tracks"] == "two.proofread.txt"
    out = np.loadtxt(tmp_path / "two.proofread.txt", delimiter=",")
    assert set(out[out[:, 0] >= 15, 1].astype(int)) == {2, 5} and set(out[out[:, 0] < 15, 1].astype(int)) == {1, 2}


def test_with_targets_a_correction_re_solves_and_the_latest_wins(tmp_path):
    page = open_page(tmp_path, n_targets=2)
    with Served(page) as s:
        assert s.request("GET", "/api/meta")[1]["propagates"]
        first = {"kind": "swap", "track": 2, "other": 1, "frame": SWAP}
        assert s.request("POST", "/api/correct", first)[0] == 200
        rows = s.request("GET", "/api/tracks?start=1&count=50")[1]["rows"]
        assert {f: lane_ids(rows, f)[30] for f in (5, 15)} == {5: 1, 15: 1}
        status, r = s.request("POST", "/api/correct", {"kind": "swap", "track": 1, "other": 2, "frame": SWAP})
        assert status == 200 and r["dropped"] == [first] and "dropped the earlier" in r["message"]
        state = s.request("GET", "/api/state")[1]
        assert [c["dropped"] for c in state["corrections"]] == [True, False]


@pytest.mark.parametrize("headers, status", [
    ({"Origin": "http://evil.example"}, 403),
    ({"Sec-Fetch-Site": "cross-site"}, 403),
    ({"Host": "evil.example"}, 403),
    ({"Content-Type": "text/plain"}, 415),
])
def test_refuses_foreign_writes(tmp_path, headers, status):
    page = open_page(tmp_path)
    with Served(page) as s:
        got, r = s.request("POST", "/api/correct", {"kind": "delete", "track": 1}, headers)
        assert got == status, r
        assert page.version == 0 and not (tmp_path / "two.corrections.jsonl").exists()
        same = {"Origin": s.url.rstrip("/"), "Sec-Fetch-Site": "same-origin"}
        assert s.request("POST", "/api/correct", {"kind": "delete", "track": 1}, same)[0] == 200


def test_refuses_oversized_bodies_and_files_outside_the_page(tmp_path):
    with Served(open_page(tmp_path)) as s:
        big = {"kind": "delete", "track": 1, "x": "a" * 70_000}
        assert s.request("POST", "/api/correct", big)[0] == 413
        for path in ("/static/../server.py", "/static/%2e%2e%2fserver.py", "/files/two.txt", "/api/tracks?count=0"):
            assert s.request("GET", path)[0] in (400, 403, 404)


def test_proofread_command_replays_the_log_and_exports(tmp_path):
    video, tracks = two_discs(tmp_path)
    log = tmp_path / "two.corrections.jsonl"
    log.write_text('{"lookalike_proofread": 1}\n' + Correction("swap", 2, 1, SWAP).to_json() + "\n")
    r = CliRunner().invoke(app, ["proofread", "--video", str(video), "--tracks", str(tracks), "--export"])
    assert r.exit_code == 0, r.output
    assert "replayed 1 corrections" in r.output
    out = np.loadtxt(tmp_path / "two.proofread.txt", delimiter=",")
    assert set(out[(out[:, 3] < 60), 1].astype(int)) == {1}  # the upper lane is 1 throughout
    r = CliRunner().invoke(app, ["proofread", "--video", str(tmp_path / "none.avi"), "--tracks", str(tracks)])
    assert r.exit_code == 2 and "no such file" in r.output
    r = CliRunner().invoke(app, ["proofread", "--video", str(tmp_path), "--tracks", str(tracks)])  # said no such file
    assert r.exit_code == 2 and "is a folder, not a file (the page reads a video file" in r.output, r.output
    r = CliRunner().invoke(app, ["proofread", "--video", str(video), "--tracks", str(tracks), "--fresh", "--export"])
    assert r.exit_code == 0 and log.with_name(log.name + ".bak").exists()
    out = np.loadtxt(tmp_path / "two.proofread.txt", delimiter=",")
    assert set(out[(out[:, 3] < 60), 1].astype(int)) == {1, 2}


def test_a_body_that_never_comes_gets_408_and_the_server_goes_on(tmp_path):
    page = open_page(tmp_path)
    with Served(page, body_timeout_s=0.5) as s:
        with socket.create_connection(("127.0.0.1", s.port), timeout=10) as slow:
            slow.sendall(b"POST /api/undo HTTP/1.1\r\nHost: 127.0.0.1\r\nContent-Type: application/json\r\n"
                         b"Content-Length: 10\r\n\r\n{")
            reply = slow.recv(4096)
        assert b" 408 " in reply.split(b"\r\n")[0]
        assert s.request("GET", "/api/state")[0] == 200


def test_a_log_replays_with_its_own_targets_and_names_a_cut_line(tmp_path):
    video, tracks = two_discs(tmp_path)
    log = tmp_path / "two.corrections.jsonl"
    head = '{"lookalike_proofread": 1, "n_targets": 2, "frame_rate": 10.0}\n'
    log.write_text(head + Correction("swap", 2, 1, SWAP).to_json() + "\n")
    r = CliRunner().invoke(app, ["proofread", "--video", str(video), "--tracks", str(tracks), "--export"])
    assert r.exit_code == 0 and "made with --targets 2" in r.output and "replayed 1 corrections" in r.output, r.output
    assert '"n_targets": 2' in log.read_text().splitlines()[0]  # the log keeps its setting
    r = CliRunner().invoke(app, ["proofread", "--video", str(video), "--tracks", str(tracks), "--targets", "3"])
    assert r.exit_code == 2 and "made with n_targets=2, but this session has n_targets=3" in r.output, r.output
    log.write_text(head + Correction("swap", 2, 1, SWAP).to_json() + '\n{"kind": "sw\n')
    r = CliRunner().invoke(app, ["proofread", "--video", str(video), "--tracks", str(tracks), "--export"])
    assert r.exit_code == 2 and "two.corrections.jsonl:3:" in r.output and "cut short" in r.output, r.output


def test_detections_in_any_layout_track_reads_solve_the_same(tmp_path):
    """``--detections`` in the layouts ``track`` reads (a header, x1,y1,x2,y2 corners): a note and the export of the
    MOTChallenge file (a header-less corner file was read as MOTChallenge columns, silently, and a header refused);
    a file without detections is one error line (was numpy's 'zero-size array')."""
    video, tracks = two_discs(tmp_path)
    rows = np.loadtxt(tracks, delimiter=",")
    corners = [[r[0], r[2], r[3], r[2] + r[4], r[3] + r[5], 1, 0] for r in rows]
    files = {"det.txt": "".join(f"{int(r[0])},-1,{r[2]:g},{r[3]:g},{r[4]:g},{r[5]:g},1,-1,-1,-1\n" for r in rows),
             "corners.txt": "".join(",".join(f"{v:g}" for v in c) + "\n" for c in corners)}
    files["header.csv"] = "frame,x1,y1,x2,y2,score,class\n" + files["corners.txt"]
    exported = {}
    for name, text in files.items():
        (tmp_path / name).write_text(text)
        out = tmp_path / f"{name}.proofread.txt"
        r = CliRunner().invoke(app, ["proofread", "--video", str(video), "--tracks", str(tracks), "--targets", "2",
                                     "--detections", str(tmp_path / name), "--export", "-o", str(out),
                                     "--log", str(tmp_path / f"{name}.log")])
        assert r.exit_code == 0 and ("note:" in r.output) == (name != "det.txt"), r.output
        exported[name] = out.read_text()
    assert exported["det.txt"] and len(set(exported.values())) == 1
    (tmp_path / "empty.txt").write_text("")
    r = CliRunner().invoke(app, ["proofread", "--video", str(video), "--tracks", str(tracks), "--targets", "2",
                                 "--detections", str(tmp_path / "empty.txt"), "--export"])
    assert r.exit_code == 2 and "--detections: " in r.output and "no detections" in r.output, r.output
