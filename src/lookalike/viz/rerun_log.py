"""Optional live view: frames, boxes and world positions logged to the Rerun viewer (``rerun-sdk``, imported lazily)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from lookalike._optional import needs
from lookalike.viz.colors import identity_colour


class RerunLogger:
    """Logs to one Rerun recording: entities ``<scene>/camera...``, ``<scene>/world/...``; times ``frame``, ``time``."""

    def __init__(self, stream: Any, rr: Any) -> None:
        self._rec, self._rr = stream, rr

    def set_time(self, frame: int, time_s: float) -> None:
        """The current frame index and its time (s) for what is logged next."""
        self._rec.set_time("frame", sequence=int(frame))
        self._rec.set_time("time", duration=float(time_s))

    def image(self, entity: str, image: np.ndarray) -> None:
        """A ``(h, w, 3)`` uint8 BGR frame."""
        self._rec.log(entity, self._rr.Image(np.ascontiguousarray(image), color_model="BGR"))

    def boxes(self, entity: str, xywh: np.ndarray, ids: np.ndarray, labels: list[str]) -> None:
        """Boxes ``xywh (n, 4)`` (px) coloured by ``ids (n,)`` (negative: false positive)."""
        b = np.asarray(xywh, dtype=float).reshape(-1, 4)
        ok = np.isfinite(b).all(axis=1)
        colours = [_rgb(int(i)) for i in np.asarray(ids).reshape(-1)[ok]]
        self._rec.log(entity, self._rr.Boxes2D(array=b[ok], array_format=self._rr.Box2DFormat.XYWH, colors=colours,
                                               labels=[t for t, k in zip(labels, ok) if k]))

    def points(self, entity: str, xy: np.ndarray, ids: np.ndarray, radius: float = 0.08) -> None:
        """World positions ``xy (n, 2)`` (m) coloured by ``ids (n,)``; NaN rows are skipped."""
        p = np.asarray(xy, dtype=float).reshape(-1, 2)
        ok = np.isfinite(p).all(axis=1)
        ident = np.asarray(ids).reshape(-1)[ok]
        self._rec.log(entity, self._rr.Points2D(p[ok], colors=[_rgb(int(i)) for i in ident],
                                                labels=[str(int(i)) for i in ident], radii=radius))

    def close(self) -> None:
        """Flush what was logged."""
        self._rec.flush()


def _rgb(identity: int) -> tuple[int, int, int]:
    b, g, r = identity_colour(identity)
    return r, g, b


def open_rerun(app_id: str = "lookalike", save: Path | str | None = None, spawn: bool = False) -> RerunLogger:
    """A logger that streams to a spawned viewer (``spawn``) or else writes a ``.rrd`` recording to ``save``."""
    with needs("rerun"):
        import rerun as rr
    if save is None and not spawn:
        raise ValueError("open_rerun: give a file to save to or spawn=True")
    rec = rr.RecordingStream(app_id)
    if spawn:
        rec.spawn()
    else:
        Path(str(save)).parent.mkdir(parents=True, exist_ok=True)
        rec.save(str(save))
    return RerunLogger(rec, rr)
