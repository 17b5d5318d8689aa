"""The proofreading page's server: a video with its tracks, corrections sent to a proofreading session
(:class:`lookalike.proofread.Session`, or anything with its methods), the log saved after each one.

Routes (JSON unless stated), on :class:`~lookalike.viz.label.server.JsonHandler`'s protections plus a refusal of
cross-origin POSTs::

    GET  /                       the page (static/proofread.html); GET /static/<name> its files
    GET  /api/meta               video facts, colours, whether corrections re-solve a closed set
    GET  /api/frame?k=           frame k (1-based) of the video as JPEG
    GET  /api/tracks?start=&count=   rows of frames start.. (1-based): [frame, id, x, y, w, h] (px)
    GET  /api/state              corrections (and which were dropped), doubtful ranges, each id's runs of
                                 frames, last change
    POST /api/correct            {"kind", "track"[, "other", "frame"]}: apply one correction (log saved at once)
    POST /api/undo               take back the last correction
    POST /api/export             write the corrected tracks (MOTChallenge) and the log"""

from __future__ import annotations

import json
import threading
from collections.abc import Callable
from http import HTTPStatus
from http.server import BaseHTTPRequestHandler
from pathlib import Path
from typing import Any, Protocol
from urllib.parse import parse_qs, urlsplit

import numpy as np

from lookalike._optional import needs
from lookalike.io.outputs import write_atomic
from lookalike.io.video_frames import video_info
from lookalike.viz.colors import PALETTE, rgb_hex
from lookalike.viz.label.server import (
    BODY_TIMEOUT_S,
    MAX_FRAMES_PER_REQUEST,
    JsonHandler,
    LabelServer,
    _BadRequest,
    _int,
)

__all__ = ["ProofreadApp", "make_proofread_server"]

MAX_DOUBTFUL = 200  # doubtful ranges listed on the page, most doubtful first


class ProofSession(Protocol):
    """What the page needs of a proofreading session (:class:`lookalike.proofread.Session` has it)."""

    rows: np.ndarray
    corrections: list[Any]
    n_targets: int | None
    last_change: Any

    @property
    def dropped(self) -> list[bool]: ...

    @property
    def propagates(self) -> bool: ...

    def apply(self, correction: Any) -> Any: ...

    def undo(self) -> Any: ...

    def doubtful(self) -> list[Any]: ...

    def save(self, tracks: Path, log: Path | None = None) -> None: ...

    def log_text(self) -> str: ...


class _Frames:
    """Frames of a video as JPEG, read in order when asked in order, else after a seek."""

    def __init__(self, path: Path) -> None:
        with needs("cv2"):
            import cv2
        self.cv2 = cv2
        self.count, self.fps, self.size = video_info(path)
        self.cap = cv2.VideoCapture(str(path))
        self.next = 1
        self.lock = threading.Lock()

    def jpeg(self, k: int) -> bytes:
        with self.lock:
            if k != self.next:
                self.cap.set(self.cv2.CAP_PROP_POS_FRAMES, k - 1)
            ok, image = self.cap.read()
            self.next = k + 1 if ok else -1
            if not ok:
                raise _BadRequest(f"the video has no frame {k}", HTTPStatus.NOT_FOUND)
            done, data = self.cv2.imencode(".jpg", image, [self.cv2.IMWRITE_JPEG_QUALITY, 85])
        if not done:
            raise ValueError(f"frame {k}: JPEG encoding failed")
        return bytes(data)


class ProofreadApp:
    """The page's state: ``session`` over the tracks of ``video``; corrections (JSON objects) become the session's by
    ``correction_from_json``; the log goes to ``log_path`` after each action, the export to ``export_path``."""

    def __init__(self, session: ProofSession, video: str | Path, log_path: str | Path, export_path: str | Path,
                 correction_from_json: Callable[[str], Any]) -> None:
        self.session = session
        self.video = Path(video)
        self.log_path, self.export_path = Path(log_path), Path(export_path)
        self.correction_from_json = correction_from_json
        self.frames = _Frames(self.video)
        self.version = 0
        self.message = ""
        self.lock = threading.Lock()

    def meta(self) -> dict[str, Any]:
        rows = self.session.rows
        last = max(self.frames.count, int(rows[:, 0].max()) if len(rows) else 1)
        return {"video": self.video.name, "n_frames": last, "width": self.frames.size[0],
                "height": self.frames.size[1], "frame_rate": self.frames.fps, "n_targets": self.session.n_targets,
                "propagates": self.session.propagates, "colours": [rgb_hex(c) for c in PALETTE],
                "log": self.log_path.name, "export": self.export_path.name}

    def tracks(self, start: int, count: int) -> dict[str, Any]:
        with self.lock:
            rows, version = self.session.rows, self.version
        sel = rows[(rows[:, 0] >= start) & (rows[:, 0] < start + count)]
        out = [[int(r[0]), int(r[1]), *(round(float(v), 1) for v in r[2:6])] for r in sel]
        return {"version": version, "start": start, "count": count, "rows": out}

    def state(self) -> dict[str, Any]:
        with self.lock:
            s = self.session
            corrections = [{**json.loads(c.to_json()), "dropped": d} for c, d in zip(s.corrections, s.dropped)]
            doubtful = [{"track": d.track, "first": d.first, "last": d.last} for d in s.doubtful()[:MAX_DOUBTFUL]]
            return {"version": self.version, "corrections": corrections, "doubtful": doubtful,
                    "spans": _spans(s.rows), "message": self.message}

    def _after(self, change: Any) -> dict[str, Any]:
        self.version += 1
        self.message = change.describe()
        write_atomic(self.log_path, self.session.log_text())
        return {"message": self.message, "version": self.version,
                "dropped": [json.loads(c.to_json()) for c in change.dropped]}

    def correct(self, body: dict[str, Any]) -> dict[str, Any]:
        correction = self.correction_from_json(json.dumps(body))
        with self.lock:
            return self._after(self.session.apply(correction))

    def undo(self) -> dict[str, Any]:
        with self.lock:
            return self._after(self.session.undo())

    def export(self) -> dict[str, Any]:
        with self.lock:
            self.session.save(self.export_path, self.log_path)
            return {"tracks": self.export_path.name, "log": self.log_path.name, "rows": len(self.session.rows)}


def _spans(rows: np.ndarray) -> dict[int, list[list[int]]]:
    """Per id, the runs of consecutive frames it has rows in: ``[[first, last], ...]`` (1-based, inclusive)."""
    order = np.lexsort((rows[:, 0], rows[:, 1]))
    ids, f = rows[order, 1].astype(int), rows[order, 0].astype(int)
    starts = np.flatnonzero(np.r_[True, (ids[1:] != ids[:-1]) | (np.diff(f) > 1)])
    ends = np.r_[starts[1:] - 1, len(f) - 1]
    out: dict[int, list[list[int]]] = {}
    for tid, a, b in zip(ids[starts].tolist(), f[starts].tolist(), f[ends].tolist()):
        out.setdefault(tid, []).append([a, b])
    return out


class _ProofreadHandler(JsonHandler):
    """Routes of :class:`ProofreadApp`; :func:`make_proofread_server` binds ``app``."""

    app: ProofreadApp
    server_version = "lookalike-proofread"

    def _get(self) -> None:
        url = urlsplit(self.path)
        query = parse_qs(url.query)
        if url.path in ("/", "/index.html"):
            self._static("proofread.html")
        elif url.path.startswith("/static/"):
            self._static(url.path[len("/static/"):])
        elif url.path == "/api/meta":
            self._json(self.app.meta())
        elif url.path == "/api/frame":
            k = _int(query, "k", 1)
            if k < 1:
                raise _BadRequest("frames are numbered from 1")
            self._send(HTTPStatus.OK, self.app.frames.jpeg(k), "image/jpeg")
        elif url.path == "/api/tracks":
            start, count = _int(query, "start", 1), _int(query, "count", 100)
            if start < 1 or not 0 < count <= MAX_FRAMES_PER_REQUEST:
                raise _BadRequest(f"need start >= 1 and 0 < count <= {MAX_FRAMES_PER_REQUEST}")
            self._json(self.app.tracks(start, count))
        elif url.path == "/api/state":
            self._json(self.app.state())
        else:
            raise _BadRequest(f"no such page {url.path!r}", HTTPStatus.NOT_FOUND)

    def _check_origin(self) -> None:
        """Refuse a write from another site: an ``Origin`` other than this server, or a cross-site fetch."""
        origin = self.headers.get("Origin")
        if origin is not None and urlsplit(origin).netloc.lower() != (self.headers.get("Host") or "").lower():
            raise _BadRequest(f"cross-origin request from {origin!r} refused", HTTPStatus.FORBIDDEN)
        if self.headers.get("Sec-Fetch-Site", "same-origin") not in ("same-origin", "none"):
            raise _BadRequest("cross-site request refused", HTTPStatus.FORBIDDEN)

    def _post(self) -> None:
        self._check_origin()
        path = urlsplit(self.path).path
        body = self._body()
        if path == "/api/correct":
            self._json(self.app.correct(body))
        elif path == "/api/undo":
            self._json(self.app.undo())
        elif path == "/api/export":
            self._json(self.app.export())
        else:
            raise _BadRequest(f"no such action {path!r}", HTTPStatus.NOT_FOUND)


def make_proofread_server(app: ProofreadApp, host: str = "127.0.0.1", port: int = 8766,
                          log: Callable[[str], None] | None = None,
                          body_timeout_s: float = BODY_TIMEOUT_S) -> LabelServer:
    """A server for ``app`` on ``host:port`` (0: any free port), with the labelling server's protections."""
    handler: type[BaseHTTPRequestHandler] = type(
        "Handler", (_ProofreadHandler,), {"app": app, "log_sink": None if log is None else staticmethod(log),
                                          "body_timeout_s": body_timeout_s})
    return LabelServer((host, port), handler)
