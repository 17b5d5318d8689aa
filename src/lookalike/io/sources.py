"""Live frame sources: a camera index or a stream URL read through OpenCV (:func:`open_live`), or a video file replayed
at its own frame rate as a simulated camera (:func:`replay_camera`). A reader thread keeps only the newest frame, so a
slow consumer skips frames instead of falling behind; the skipped frames are counted (:attr:`LiveSource.dropped`)."""

from __future__ import annotations

import re
import signal
import threading
import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from lookalike._optional import needs

__all__ = ["LiveFrame", "LiveSource", "SignalStop", "is_live", "open_live", "replay_camera"]

_URL = re.compile(r"^(rtsp|rtsps|rtmp|http|https|udp|tcp|srt)://", re.IGNORECASE)
STAMP_CHECK_S = 2.0  # seconds of a live stream before its stamps are compared with the wall clock
STAMP_DRIFT = 0.1  # the share by which they may differ (jitter; 30 frames/s stamped as 25 is 0.17)
_OPEN_TIMEOUT_S = 10.0  # OpenCV's own open timeout is longer; a stream that sends nothing in this time is refused


def is_live(spec: str | None) -> bool:
    """Whether ``--video``'s text names a live source: a camera index (``0``) that is not a file here, or a stream
    URL (``rtsp://``, ``http://``, ...)."""
    if spec is None:
        return False
    if _URL.match(spec):
        return True
    return spec.isdigit() and not Path(spec).exists()


@dataclass(frozen=True)
class LiveFrame:
    """One frame of a live source: ``image`` ``(h, w, 3)`` BGR uint8, ``number`` the 0-based count of frames the
    source delivered before it (dropped ones included), ``time`` seconds since the source's first frame."""

    image: np.ndarray
    number: int
    time: float


Read = Callable[[], "tuple[np.ndarray, float | None] | None"]
"""Reads the next frame: ``(image, stream time in s or None)``, or None at the end of the source."""


class LiveSource:
    """The newest frame of a source read on its own thread. Iterating yields :class:`LiveFrame` objects as they
    come, waiting for the next one; a frame replaced before it was taken counts in :attr:`dropped`. Stamps: the stream's
    own (``clock == "stream"``) when ``read`` gives them, else the wall clock (rounded to the period of
    ``frame_rate`` when given); never decreasing. With ``realtime`` (a camera or a live stream), stream stamps that
    have drifted from the wall clock by more than :data:`STAMP_DRIFT` after :data:`STAMP_CHECK_S` seconds (FFmpeg
    invents 25 frames/s for an MJPEG stream) give way to the wall clock from then on. ``now``: the wall clock (s)."""

    def __init__(self, read: Read, name: str, frame_rate: float | None = None,
                 release: Callable[[], None] | None = None, *, realtime: bool = False,
                 now: Callable[[], float] = time.monotonic) -> None:
        self.name, self.frame_rate = name, frame_rate
        self._read, self._release = read, release
        self._realtime, self._now = realtime, now
        self._cond = threading.Condition()
        self._slot: LiveFrame | None = None
        self._ended = self._closed = False
        self.error: BaseException | None = None  # what stopped the reader, if not the end of the source
        self.delivered = 0  # frames the source gave
        self.taken = 0  # frames handed to the consumer
        self.dropped = 0  # frames replaced before the consumer took them
        self.clock = "wall clock"
        self._thread = threading.Thread(target=self._run, name=f"lookalike-live-{name}", daemon=True)
        self._thread.start()

    def _run(self) -> None:
        start = self._now()
        first: float | None = None
        last = first_wall = offset = 0.0
        trusted = True  # the stream's stamps, while they keep to the wall clock
        try:
            while not self._closed:
                got = self._read()
                if got is None:
                    break
                image, stamp = got
                wall = self._now() - start
                if stamp is not None and first is None:
                    first, first_wall = stamp, wall
                if stamp is not None and first is not None and trusted:
                    t, self.clock = stamp - first, "stream"
                    since = wall - first_wall
                    if self._realtime and since >= STAMP_CHECK_S and abs(t - since) > STAMP_DRIFT * since:
                        trusted, offset = False, last - wall  # the wall clock on from here, without a jump
                        self.clock = f"wall clock (the stream's stamps ran at {t / since:.2f}× real time)"
                        t = wall + offset
                elif not trusted:
                    t = wall + offset
                else:  # on the source's nominal frame period when it declares one (steady steps for the tracker)
                    t = wall
                    if self.frame_rate:
                        t = round(t * self.frame_rate) / self.frame_rate
                last = max(last, t)
                with self._cond:
                    if self._slot is not None:
                        self.dropped += 1
                    self._slot = LiveFrame(image, self.delivered, last)
                    self.delivered += 1
                    self._cond.notify_all()
        except BaseException as exc:  # noqa: BLE001 (handed to the consumer)
            self.error = exc
        finally:
            with self._cond:
                self._ended = True
                self._cond.notify_all()
            if self._closed:  # closed while this read was under way: released now that it has returned
                self._release_once()

    def _release_once(self) -> None:
        """Release the source, once (from :meth:`close` or from the reader, whichever comes last)."""
        with self._cond:
            release, self._release = self._release, None
        if release is not None:
            release()

    def next(self, timeout: float | None = None) -> LiveFrame | None:
        """The newest frame not yet taken, waiting up to ``timeout`` s (None: until one comes); None at the end of
        the source, when closed, or after ``timeout``."""
        with self._cond:
            self._cond.wait_for(lambda: self._slot is not None or self._ended or self._closed, timeout)
            frame, self._slot = self._slot, None
        if frame is not None:
            self.taken += 1
        return frame

    @property
    def ended(self) -> bool:
        """Whether the source has no more frames (its end, an error or :meth:`close`)."""
        return (self._ended or self._closed) and self._slot is None

    def __iter__(self) -> Iterator[LiveFrame]:
        while True:
            frame = self.next(timeout=0.5)
            if frame is not None:
                yield frame
            elif self.ended:
                return

    def close(self) -> None:
        """Stop reading and release the source (the frame waiting, if any, is neither taken nor dropped). A read
        still under way after 5 s (a stalled stream) is not cut: the reader releases the source when it returns."""
        with self._cond:
            self._closed = True
            self._slot = None
            self._cond.notify_all()
        self._thread.join(timeout=5.0)
        if not self._thread.is_alive():
            self._release_once()

    def __enter__(self) -> LiveSource:
        return self

    def __exit__(self, *exc: Any) -> None:
        self.close()


def open_live(spec: str) -> LiveSource:
    """A :class:`LiveSource` on a camera index (``"0"``) or a stream URL through OpenCV; ``ValueError`` when it
    cannot be opened or sends no frame. Stream stamps from ``CAP_PROP_POS_MSEC`` when positive, else the wall
    clock."""
    with needs("cv2"):
        import cv2

    target: int | str = int(spec) if spec.isdigit() else spec
    cap = cv2.VideoCapture(target) if isinstance(target, int) else cv2.VideoCapture(
        target, cv2.CAP_FFMPEG, [cv2.CAP_PROP_OPEN_TIMEOUT_MSEC, int(_OPEN_TIMEOUT_S * 1000),
                                 cv2.CAP_PROP_READ_TIMEOUT_MSEC, int(_OPEN_TIMEOUT_S * 1000)])
    if not cap.isOpened():
        cap.release()
        what = f"camera {spec}" if isinstance(target, int) else spec
        raise ValueError(f"video: cannot open {what} (OpenCV found no such camera or stream)")
    rate = float(cap.get(cv2.CAP_PROP_FPS) or 0.0)

    def read() -> tuple[np.ndarray, float | None] | None:
        ok, image = cap.read()
        if not ok or image is None:
            return None
        msec = float(cap.get(cv2.CAP_PROP_POS_MSEC) or 0.0)
        return image, (msec / 1000.0 if msec > 0 else None)

    return LiveSource(read, spec, rate if 0 < rate < 1000 else None, cap.release, realtime=True)


def replay_camera(path: str | Path, speed: float = 1.0, frame_rate: float | None = None) -> LiveSource:
    """A simulated camera: the frames of the video file ``path`` delivered at its frame rate (``frame_rate`` if
    given) times ``speed``, whether or not the consumer keeps up, stamped with the file's own times."""
    with needs("cv2"):
        import cv2

    cap = cv2.VideoCapture(str(path))
    if not cap.isOpened():
        cap.release()
        raise ValueError(f"video: cannot open {path}")
    rate = frame_rate or float(cap.get(cv2.CAP_PROP_FPS) or 0.0) or 25.0
    period = 1.0 / (rate * speed)
    due: list[float] = []  # when the next frame is due (monotonic s), after the first
    count = [0]

    def read() -> tuple[np.ndarray, float | None] | None:
        ok, image = cap.read()
        if not ok or image is None:
            return None
        if due:
            time.sleep(max(due[0] - time.monotonic(), 0.0))
            due[0] += period
        else:
            due.append(time.monotonic() + period)
        k = count[0]
        count[0] = k + 1
        return image, k / rate

    return LiveSource(read, Path(path).name, rate, cap.release)


class SignalStop:
    """A stop flag set by SIGINT (Ctrl-C) or SIGTERM while in a ``with`` block (handlers installed on the main thread
    only), by :meth:`set`, or ``duration_s`` seconds after it was made (0: never). ``stop()`` and ``bool(stop)`` say
    whether to stop; ``signal`` is the signal that set it, ``reason`` what did. With ``interrupt_twice`` a second
    Ctrl-C raises ``KeyboardInterrupt`` at once."""

    def __init__(self, duration_s: float = 0.0, *, interrupt_twice: bool = False) -> None:
        self.deadline = time.monotonic() + duration_s if duration_s > 0 else None
        self.interrupt_twice = interrupt_twice
        self.signal: int | None = None
        self.reason = ""
        self._event = threading.Event()
        self._old: dict[int, Any] = {}

    def set(self, reason: str = "stopped") -> None:
        """Ask the run to stop after the frame in hand."""
        self.reason = self.reason or reason
        self._event.set()

    def __bool__(self) -> bool:
        return self._event.is_set() or (self.deadline is not None and time.monotonic() >= self.deadline)

    __call__ = __bool__

    def _handle(self, signum: int, _frame: object) -> None:
        if self.interrupt_twice and signum == signal.SIGINT and self._event.is_set():
            raise KeyboardInterrupt
        self.signal = signum
        self.set(signal.Signals(signum).name)

    def __enter__(self) -> SignalStop:  # noqa: PYI034
        if threading.current_thread() is threading.main_thread():
            for sig in (signal.SIGINT, signal.SIGTERM):
                self._old[sig] = signal.signal(sig, self._handle)
        return self

    def __exit__(self, *exc: object) -> None:
        for sig, handler in self._old.items():
            signal.signal(sig, handler)
        self._old.clear()
