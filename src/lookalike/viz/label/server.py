"""The labelling page's HTTP server (standard library ``ThreadingHTTPServer``).

Routes (JSON unless stated)::

    GET  /                       the page (static/index.html); GET /static/<name> its files
    GET  /api/meta               sequence facts, colours, mode, image pattern
    GET  /api/frames?start=&count=   frames' detections and latest reports (truth unless benchmark)
    GET  /api/labels             all labels and the benchmark state
    POST /api/label              {"frame", "detection", "label"}: set one label (saved at once)
    POST /api/benchmark/start    start timing;  POST /api/benchmark/finish  stop, score, write the result file
    GET  /api/score              success rate against the truth (benchmark mode: after finishing)
    POST /api/export             write <stem>.labelled.jsonl and <stem>.labels.mot.txt beside the sequence
    GET  /files/<path>           a file inside the sequence's folder (benchmark mode: frame images only)

Foreign ``Host`` headers and non-JSON POSTs are refused; idle connections close after ``IDLE_TIMEOUT_S``, slow bodies
get 408 after ``BODY_TIMEOUT_S``."""

from __future__ import annotations

import json
import mimetypes
import time
from collections.abc import Callable
from http import HTTPStatus
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from pathlib import Path
from typing import Any, cast
from urllib.parse import parse_qs, unquote, urlsplit

import numpy as np

from lookalike.sim import RobotSequence
from lookalike.viz.colors import FALSE_POSITIVE, identity_colour, rgb_hex
from lookalike.viz.label.exports import export_mot, export_truth
from lookalike.viz.label.human import check_labeller, human_result, human_result_path, write_human_result
from lookalike.viz.label.store import LabelStore, score_labels

STATIC_DIR = Path(__file__).resolve().parent / "static"
MAX_BODY_BYTES = 64 * 1024
MAX_FRAMES_PER_REQUEST = 500
IMAGE_SUFFIXES = (".png", ".jpg", ".jpeg")
IDLE_TIMEOUT_S = 10.0  # a connection silent this long is closed
BODY_TIMEOUT_S = 5.0  # a request body must arrive completely within this
LISTEN_BACKLOG = 128


class LabelApp:
    """What the server serves: the sequence read from ``sequence_path`` (only its folder is served), its label
    ``store``, and whether it is a ``benchmark`` (truth never sent; timed; scored at the end, the result file in
    ``results_dir``, default the sequence's folder, named after ``labeller``)."""

    def __init__(self, sequence_path: str | Path, sequence: RobotSequence, store: LabelStore,
                 benchmark: bool = False, labeller: str = "anonymous", results_dir: str | Path | None = None) -> None:
        self.sequence_path = Path(sequence_path).resolve()
        self.folder = self.sequence_path.parent
        self.sequence = sequence
        self.store = store
        self.benchmark = benchmark
        self.labeller = check_labeller(labeller)
        self.result_path = human_result_path(self.sequence_path, self.labeller, results_dir)
        self.truth = sequence.true_labels()
        self._reports = _latest_reports(sequence)
        self.image_pattern = _find_images(self.folder, self.sequence_path.stem)

    def meta(self) -> dict[str, Any]:
        cfg = self.sequence.config
        return {
            "name": self.sequence_path.name, "n_frames": len(self.sequence), "n_agents": cfg.n_agents,
            "max_detections": cfg.max_detections, "benchmark": self.benchmark, "has_truth": not self.benchmark,
            "fov_rad": cfg.observer.fov_rad, "max_range_m": cfg.observer.max_range_m,
            "colours": [rgb_hex(identity_colour(i)) for i in range(cfg.n_agents)],
            "fp_colour": rgb_hex(FALSE_POSITIVE), "source": self.store.source, "image_pattern": self.image_pattern,
            "labeller": self.labeller,
        }

    def frames(self, start: int, count: int) -> list[dict[str, Any]]:
        a = self.sequence.arrays
        out = []
        for k in range(max(start, 0), min(start + count, len(a))):
            n = int(a.det_valid[k].sum())
            det = [{"x": float(a.det_position[k, j, 0]), "y": float(a.det_position[k, j, 1]),
                    "heading": float(a.det_heading[k, j]), "score": float(a.det_score[k, j])} for j in range(n)]
            row: dict[str, Any] = {"frame": k, "time": float(a.time[k]), "detections": det, "reports": self._reports[k]}
            if not self.benchmark:
                row["truth"] = self.truth[k].tolist()
            out.append(row)
        return out

    def score(self) -> dict[str, Any]:
        return score_labels(self.store.snapshot(), self.truth, self.sequence.config.n_agents)

    def finish_benchmark(self) -> dict[str, Any]:
        """Stop and score the benchmark session (idempotent), write its result file and return its entry."""
        bench = self.store.finish_benchmark(self.truth)
        self.write_result()
        return bench

    def write_result(self) -> Path:
        """Write the finished benchmark session's result file; ``ValueError`` if no session has finished."""
        bench = self.store.benchmark
        if bench is None or bench.get("finished_at") is None:
            raise ValueError(f"{self.store.path.name}: no finished benchmark session")
        cfg = self.sequence.config
        result = human_result(self.sequence_path.name, self.labeller, cfg.n_agents, cfg.max_detections,
                              len(self.sequence), bench)
        return write_human_result(self.result_path, result)

    def export(self) -> dict[str, Any]:
        labels = self.store.snapshot()
        stem = self.sequence_path.stem
        truth_path, unset = export_truth(self.sequence, labels, self.folder / f"{stem}.labelled.jsonl")
        mot_path, rows = export_mot(self.sequence, labels, self.folder / f"{stem}.labels.mot.txt")
        return {"truth": truth_path.name, "mot": mot_path.name, "unset": unset, "mot_rows": rows}


def _latest_reports(sequence: RobotSequence) -> list[list[dict[str, Any]]]:
    """Per frame, each agent's latest received report so far: agent, heading (rad), age (s)."""
    a, r = sequence.arrays, sequence.arrays.reports
    n = sequence.config.n_agents
    heading, sent = np.full(n, np.nan), np.full(n, np.nan)
    out = []
    for k in range(len(a)):
        for i in range(r.frame_offsets[k], r.frame_offsets[k + 1]):
            agent = int(r.agent_id[i])
            if 0 <= agent < n and not r.t_sent[i] < sent[agent]:
                heading[agent], sent[agent] = r.heading[i], r.t_sent[i]
        out.append([{"agent": j, "heading": float(heading[j]), "age": float(a.time[k] - sent[j])}
                    for j in range(n) if np.isfinite(heading[j])])
    return out


def _find_images(folder: Path, stem: str) -> str | None:
    """``files/<dir>/{frame:06d}<ext>`` when ``<stem>_frames/`` or ``img1/`` holds 1-based frame images."""
    for name in (f"{stem}_frames", "img1"):
        d = folder / name
        if d.is_dir():
            for ext in IMAGE_SUFFIXES:
                if (d / f"000001{ext}").is_file():
                    return f"files/{name}/{{frame:06d}}{ext}"
    return None


class _BadRequest(Exception):
    def __init__(self, message: str, status: HTTPStatus = HTTPStatus.BAD_REQUEST) -> None:
        super().__init__(message)
        self.status = status


def _int(query: dict[str, list[str]], name: str, default: int) -> int:
    try:
        return int(query.get(name, [str(default)])[0])
    except ValueError:
        raise _BadRequest(f"query parameter {name} must be an integer") from None


class JsonHandler(BaseHTTPRequestHandler):
    """What the labelling and proofreading pages share: Host check, JSON answers, static files, bounded and timed
    JSON bodies, errors answered without taking the server down; subclasses route in ``_get`` and ``_post``."""

    log_sink: Callable[[str], None] | None = None
    server_version = "lookalike"
    timeout = IDLE_TIMEOUT_S  # seconds a connection may stay silent
    body_timeout_s = BODY_TIMEOUT_S

    def log_message(self, format: str, *args: Any) -> None:
        if self.log_sink is not None:
            self.log_sink(f"{self.address_string()} {format % args}")

    def _send(self, status: HTTPStatus, body: bytes, content_type: str) -> None:
        self.send_response(status)
        self.send_header("Content-Type", content_type)
        self.send_header("Content-Length", str(len(body)))
        self.send_header("Cache-Control", "no-store")
        self.send_header("X-Content-Type-Options", "nosniff")
        self.end_headers()
        if self.command != "HEAD":
            self.wfile.write(body)

    def _json(self, payload: Any, status: HTTPStatus = HTTPStatus.OK) -> None:
        self._send(status, json.dumps(payload, allow_nan=False).encode(), "application/json")

    def _check_host(self) -> None:
        host = (self.headers.get("Host") or "").rsplit(":", 1)[0].strip("[]").lower()
        bound = cast(tuple[str, int], self.server.server_address)[0]
        if bound in ("127.0.0.1", "::1", "localhost") and host not in ("127.0.0.1", "localhost", "::1"):
            raise _BadRequest(f"unexpected Host header {host!r}", HTTPStatus.FORBIDDEN)

    def _dispatch(self, route: Callable[[], None]) -> None:
        try:
            self._check_host()
            route()
        except _BadRequest as exc:
            self._json({"error": str(exc)}, exc.status)
        except ValueError as exc:
            self._json({"error": str(exc)}, HTTPStatus.BAD_REQUEST)
        except TimeoutError:
            self.close_connection = True
            self._json({"error": f"request body not received within {self.body_timeout_s:g} s"},
                       HTTPStatus.REQUEST_TIMEOUT)
        except (BrokenPipeError, ConnectionResetError):
            pass
        except Exception as exc:  # noqa: BLE001 (a bug must not take the server down)
            self._json({"error": f"internal error: {exc!r}"}, HTTPStatus.INTERNAL_SERVER_ERROR)

    def do_GET(self) -> None:
        self._dispatch(self._get)

    def do_HEAD(self) -> None:
        self._dispatch(self._get)

    def do_POST(self) -> None:
        self._dispatch(self._post)

    def _get(self) -> None:
        raise _BadRequest(f"no such page {self.path!r}", HTTPStatus.NOT_FOUND)

    def _post(self) -> None:
        raise _BadRequest(f"no such action {self.path!r}", HTTPStatus.NOT_FOUND)

    def _static(self, name: str) -> None:
        if name not in {p.name for p in STATIC_DIR.iterdir() if p.is_file()}:
            raise _BadRequest(f"no static file {name!r}", HTTPStatus.NOT_FOUND)
        p = STATIC_DIR / name
        self._send(HTTPStatus.OK, p.read_bytes(), mimetypes.guess_type(p.name)[0] or "application/octet-stream")

    def _body(self) -> dict[str, Any]:
        ctype = (self.headers.get("Content-Type") or "").split(";")[0].strip().lower()
        if ctype != "application/json":
            raise _BadRequest("POST bodies must be application/json", HTTPStatus.UNSUPPORTED_MEDIA_TYPE)
        try:
            length = int(self.headers.get("Content-Length", ""))
        except ValueError:
            raise _BadRequest("Content-Length required", HTTPStatus.LENGTH_REQUIRED) from None
        if not 0 <= length <= MAX_BODY_BYTES:
            raise _BadRequest(f"body over {MAX_BODY_BYTES} bytes", HTTPStatus.REQUEST_ENTITY_TOO_LARGE)
        raw = self._read_body(length) if length else b"{}"
        try:
            body = json.loads(raw)
        except (json.JSONDecodeError, UnicodeDecodeError):
            raise _BadRequest("body is not JSON") from None
        except RecursionError:
            raise _BadRequest("body is nested too deeply") from None
        if not isinstance(body, dict):
            raise _BadRequest("body must be a JSON object")
        return body

    def _read_body(self, length: int) -> bytes:
        """``length`` bytes of body within ``body_timeout_s`` in all (``TimeoutError`` otherwise)."""
        deadline = time.monotonic() + self.body_timeout_s
        chunks, got = [], 0
        try:
            while got < length:
                remaining = deadline - time.monotonic()
                if remaining <= 0:
                    raise TimeoutError
                self.connection.settimeout(remaining)
                chunk = self.rfile.read1(length - got)
                if not chunk:
                    raise _BadRequest(f"body ended after {got} of {length} bytes")
                chunks.append(chunk)
                got += len(chunk)
        finally:
            self.connection.settimeout(self.timeout)
        return b"".join(chunks)


class _Handler(JsonHandler):
    """Routes of the labelling app; :func:`make_handler` binds ``app`` and ``log_sink``."""

    app: LabelApp
    server_version = "lookalike-label"

    def _get(self) -> None:
        url = urlsplit(self.path)
        query = parse_qs(url.query)
        path = url.path
        if path in ("/", "/index.html"):
            self._static("index.html")
        elif path.startswith("/static/"):
            self._static(path[len("/static/"):])
        elif path.startswith("/files/"):
            self._file(path[len("/files/"):])
        elif path == "/api/meta":
            self._json(self.app.meta())
        elif path == "/api/frames":
            start, count = _int(query, "start", 0), _int(query, "count", 100)
            if start < 0 or not 0 < count <= MAX_FRAMES_PER_REQUEST:
                raise _BadRequest(f"need start >= 0 and 0 < count <= {MAX_FRAMES_PER_REQUEST}")
            self._json({"frames": self.app.frames(start, count)})
        elif path == "/api/labels":
            self._json({"labels": self.app.store.snapshot(), "benchmark": self.app.store.benchmark})
        elif path == "/api/score":
            bench = self.app.store.benchmark
            if self.app.benchmark and not (bench and bench.get("finished_at") is not None):
                raise _BadRequest("the score is shown when the benchmark session ends", HTTPStatus.FORBIDDEN)
            self._json(self.app.score())
        else:
            raise _BadRequest(f"no such page {path!r}", HTTPStatus.NOT_FOUND)

    def _file(self, rel: str) -> None:
        rel = unquote(rel)
        if "\x00" in rel:
            raise _BadRequest("NUL in path")
        target = (self.app.folder / rel).resolve()
        if not target.is_relative_to(self.app.folder) or target == self.app.folder:
            raise _BadRequest("outside the sequence folder", HTTPStatus.FORBIDDEN)
        if not target.is_file():
            raise _BadRequest(f"no file {rel!r}", HTTPStatus.NOT_FOUND)
        if self.app.benchmark and not _is_frame_image(target, self.app.folder, self.app.image_pattern):
            raise _BadRequest("benchmark mode serves the frame images only", HTTPStatus.FORBIDDEN)
        ctype = mimetypes.guess_type(target.name)[0] or "application/octet-stream"
        self._send(HTTPStatus.OK, target.read_bytes(), ctype)

    def _post(self) -> None:
        path = urlsplit(self.path).path
        body = self._body()
        if path == "/api/label":
            missing = [k for k in ("frame", "detection", "label") if k not in body]
            if missing:
                raise _BadRequest(f"missing {', '.join(missing)}")
            self.app.store.set_label(body["frame"], body["detection"], body["label"])
            self._json({"ok": True})
        elif path == "/api/benchmark/start":
            if not self.app.benchmark:
                raise _BadRequest("not in benchmark mode", HTTPStatus.CONFLICT)
            self._json({"benchmark": self.app.store.start_benchmark()})
        elif path == "/api/benchmark/finish":
            if not self.app.benchmark:
                raise _BadRequest("not in benchmark mode", HTTPStatus.CONFLICT)
            self._json({"benchmark": self.app.finish_benchmark()})
        elif path == "/api/export":
            self._json(self.app.export())
        else:
            raise _BadRequest(f"no such action {path!r}", HTTPStatus.NOT_FOUND)


def _is_frame_image(target: Path, folder: Path, pattern: str | None) -> bool:
    """Whether ``target`` is an image inside the folder of the sequence's frame images."""
    if pattern is None or target.suffix.lower() not in IMAGE_SUFFIXES:
        return False
    images = (folder / pattern.split("/")[1]).resolve()
    return target.parent == images


def make_handler(app: LabelApp, log: Callable[[str], None] | None = None,
                 body_timeout_s: float = BODY_TIMEOUT_S) -> type[BaseHTTPRequestHandler]:
    """A request handler class bound to ``app`` (``log`` receives one line per request)."""
    handler: type[BaseHTTPRequestHandler] = type(
        "Handler", (_Handler,), {"app": app, "log_sink": None if log is None else staticmethod(log),
                                 "body_timeout_s": body_timeout_s}
    )
    return handler


class LabelServer(ThreadingHTTPServer):
    """``ThreadingHTTPServer`` with a listen backlog of ``LISTEN_BACKLOG`` and daemon threads."""

    request_queue_size = LISTEN_BACKLOG
    daemon_threads = True


def make_server(app: LabelApp, host: str = "127.0.0.1", port: int = 8765,
                log: Callable[[str], None] | None = None, body_timeout_s: float = BODY_TIMEOUT_S) -> LabelServer:
    """A server for ``app`` on ``host:port`` (0: any free port); bodies slower than ``body_timeout_s`` get 408."""
    return LabelServer((host, port), make_handler(app, log, body_timeout_s))
