"""Writing annotated videos, animated GIFs and still images (reading videos: :mod:`lookalike.io.video_frames`).
MP4s are H.264 through PyAV (the ``viz`` extra) so browsers play them, else OpenCV's ``mp4v``; PyAV, OpenCV and
Pillow are imported lazily."""

from __future__ import annotations

import os
from fractions import Fraction
from pathlib import Path
from types import TracebackType
from typing import Any

import numpy as np

from lookalike._optional import needs
from lookalike.io.outputs import atomic_path, write_atomic
from lookalike.io.rules import temp_beside, write_target


class VideoWriter:
    """An H.264 MP4 written frame by frame (``(h, w, 3)`` uint8 BGR, odd sizes padded); a context manager. ``gif``
    also gets every ``gif_every``-th of the first ``gif_frames`` frames, ``gif_width`` px wide. ``atomic``: the MP4 is
    written beside ``path`` and renamed onto it by :meth:`close`; a block that raises (Ctrl-C included) or
    :meth:`abort` removes it and writes no GIF, so a video already at ``path`` stays as it was."""

    def __init__(self, path: Path | str, fps: float, gif: Path | str | None = None, gif_every: int = 2,
                 gif_frames: int = 120, gif_width: int = 640, atomic: bool = False) -> None:
        if not fps > 0:
            raise ValueError(f"fps: must be positive, got {fps!r}")
        if gif_every < 1 or gif_frames < 1 or gif_width < 16:
            raise ValueError(f"gif_every/gif_frames/gif_width: got {gif_every}, {gif_frames}, {gif_width}")
        self.path, self.fps = Path(path), float(fps)
        self.gif = Path(gif) if gif is not None else None
        self.gif_every, self.gif_frames, self.gif_width = gif_every, gif_frames, gif_width
        self.count = 0
        self._writer: Any = None  # an _H264Writer (or cv2.VideoWriter) once the first frame fixes the size
        self._size: tuple[int, int] | None = None
        self._gif_images: list[np.ndarray] = []
        self.atomic = atomic
        self._tmp: Path | None = None  # (atomic) the file written until close() renames it onto path

    def write(self, image: np.ndarray) -> None:
        """Append one frame."""
        with needs("cv2"):
            import cv2

        img = np.asarray(image)
        if img.ndim != 3 or img.shape[2] != 3 or img.dtype != np.uint8:
            raise ValueError(f"image: expected (h, w, 3) uint8 BGR, got {img.shape} {img.dtype}")
        size = (img.shape[1], img.shape[0])
        if self._writer is None:
            self.path.parent.mkdir(parents=True, exist_ok=True)
            target = self.path
            if self.atomic:
                fd, self._tmp = temp_beside(write_target(self.path))
                os.close(fd)
                target = self._tmp
            self._writer = _open_writer(target, self.fps, size)
            self._size = size
        elif size != self._size:
            raise ValueError(f"image: frame {self.count} is {size}, earlier frames {self._size}")
        self._writer.write(np.ascontiguousarray(img))
        if self.gif is not None and self.count < self.gif_frames and self.count % self.gif_every == 0:
            h = round(img.shape[0] * self.gif_width / img.shape[1])
            shrink = self.gif_width < img.shape[1]
            self._gif_images.append(cv2.resize(img, (self.gif_width, h),
                                               interpolation=cv2.INTER_AREA if shrink else cv2.INTER_LINEAR))
        self.count += 1

    def close(self) -> None:
        """Finalise the MP4 (and write the GIF)."""
        if self._writer is not None:
            self._writer.release()
            self._writer = None
        if self._tmp is not None:
            os.replace(self._tmp, write_target(self.path))
            self._tmp = None
        if self.gif is not None and self._gif_images:
            write_gif(self.gif, self._gif_images, fps=self.fps / self.gif_every)
            self._gif_images = []

    def abort(self) -> None:
        """Stop without finishing: no GIF; with ``atomic`` the unfinished MP4 is removed (``path`` untouched)."""
        self._gif_images = []
        try:
            if self._writer is not None:
                self._writer.release()
        finally:
            self._writer = None
            if self._tmp is not None:
                self._tmp.unlink(missing_ok=True)
                self._tmp = None

    def __enter__(self) -> VideoWriter:
        return self

    def __exit__(self, exc_type: type[BaseException] | None, exc: BaseException | None,
                 tb: TracebackType | None) -> None:
        if exc_type is not None and self.atomic:
            self.abort()
        else:
            self.close()


MP4_SUFFIXES = (".mp4", ".m4v", ".mov")


class _H264Writer:
    """H.264 MP4 through PyAV: yuv420p, even size (padded), ``+faststart`` for streaming."""

    def __init__(self, path: Path, fps: float, size: tuple[int, int]) -> None:
        with needs("av"):
            import av

        self.width, self.height = size[0] + size[0] % 2, size[1] + size[1] % 2
        faststart = {"movflags": "+faststart"}  # an MP4's or QuickTime file's option only (AVI, MKV: none)
        try:
            self.container: Any = av.open(str(path), mode="w",
                                          options=faststart if path.suffix.lower() in MP4_SUFFIXES else {})
        except ValueError:  # FFmpeg cannot tell a container from the name (no or an unknown suffix): an MP4
            self.container = av.open(str(path), mode="w", format="mp4", options=faststart)
        self.stream: Any = self.container.add_stream("libx264", rate=Fraction(fps).limit_denominator(1001))
        self.stream.width, self.stream.height, self.stream.pix_fmt = self.width, self.height, "yuv420p"
        self.stream.options = {"crf": "23", "preset": "veryfast"}
        self._frame_type = av.VideoFrame

    def write(self, img: np.ndarray) -> None:
        if img.shape[1] != self.width or img.shape[0] != self.height:
            padded = np.zeros((self.height, self.width, 3), np.uint8)
            padded[: img.shape[0], : img.shape[1]] = img
            img = padded
        frame = self._frame_type.from_ndarray(np.ascontiguousarray(img), format="bgr24")
        for packet in self.stream.encode(frame):
            self.container.mux(packet)

    def release(self) -> None:
        for packet in self.stream.encode(None):
            self.container.mux(packet)
        self.container.close()


def _open_writer(path: Path, fps: float, size: tuple[int, int]) -> Any:
    """An H.264 writer (PyAV), else OpenCV's mp4v (which browsers do not play)."""
    try:
        with needs("av"):
            import av  # noqa: F401
    except ImportError:
        with needs("cv2"):
            import cv2

        writer = cv2.VideoWriter(str(path), cv2.VideoWriter.fourcc(*"mp4v"), fps, size)
        if not writer.isOpened():
            raise ValueError(f"path: OpenCV cannot write an MP4 video at {path}") from None
        return writer
    try:
        return _H264Writer(path, fps, size)
    except Exception as exc:  # PyAV raises its own error types (e.g. a folder that cannot be written)
        raise ValueError(f"path: cannot write an H.264 video at {path}: {exc}") from None


def write_gif(path: Path | str, images: list[np.ndarray], fps: float) -> Path:
    """An animated, looping GIF of BGR ``images`` at ``fps`` frames per second (adaptive palette)."""
    from PIL import Image

    if not images:
        raise ValueError("images: no frames for the GIF")
    if not fps > 0:
        raise ValueError(f"fps: must be positive, got {fps!r}")
    frames = [Image.fromarray(np.ascontiguousarray(im[..., ::-1])).quantize(colors=128) for im in images]
    out = Path(path)
    with atomic_path(out) as tmp:  # interrupted: no half-written GIF, an earlier one stays
        frames[0].save(tmp, format="GIF", save_all=True, append_images=frames[1:], duration=round(1000 / fps),
                       loop=0, optimize=False)
    return out


def write_png(path: Path | str, image: np.ndarray) -> Path:
    """A PNG of the BGR ``image``, whatever the name, through :func:`~lookalike.io.outputs.write_atomic` (interrupted:
    no half-written image, an earlier one stays)."""
    with needs("cv2"):
        import cv2

    done, data = cv2.imencode(".png", np.ascontiguousarray(image))
    if not done:
        raise ValueError(f"{path}: OpenCV cannot encode this image as PNG (shape {np.shape(image)})")
    return write_atomic(path, data.tobytes())
