"""Reading the frames of a video file or an image folder (OpenCV, imported lazily): every frame in order, the frame
count and rate a container declares, and a clear error for a file that cannot be opened or stops early."""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

import numpy as np

from lookalike._optional import needs

IMAGE_SUFFIXES = (".jpg", ".jpeg", ".png", ".bmp")


def source_frames(source: Path | str) -> tuple[Iterator[np.ndarray], int, float]:
    """Frames of a video file or image folder (by name), the frame count and rate (30 for folders)."""
    with needs("cv2"):
        import cv2

    p = Path(source)
    if p.is_dir():
        paths = sorted(q for q in p.iterdir() if q.suffix.lower() in IMAGE_SUFFIXES)
        if not paths:
            raise ValueError(f"video: folder {p} holds no images ({', '.join(IMAGE_SUFFIXES)})")

        def images() -> Iterator[np.ndarray]:
            first = None
            for q in paths:
                img = cv2.imread(str(q), cv2.IMREAD_COLOR)
                if img is None:
                    raise ValueError(f"video: cannot read image {q}")
                first = img.shape if first is None else first
                if img.shape != first:
                    raise ValueError(f"video: {q} is {img.shape[1]}x{img.shape[0]} px, the folder's first image "
                                     f"{first[1]}x{first[0]}; every frame needs one size")
                yield img

        return images(), len(paths), 30.0
    n, fps, _ = video_info(p)
    return _all_frames(p, n), n, fps


def _all_frames(path: Path, declared: int) -> Iterator[np.ndarray]:
    """:func:`read_frames`, then ``ValueError`` when it stopped well short of the ``declared`` count."""
    count = 0
    for img in read_frames(path):
        count += 1
        yield img
    if declared > 0 and count < declared - max(2, declared // 20):
        raise ValueError(f"video: {path} declares {declared} frames but only {count} could be read "
                         "(truncated or damaged?)")


@contextmanager
def _capture(path: Path | str) -> Iterator[Any]:
    """An open ``cv2.VideoCapture`` of ``path``, released on exit; a clear error when it cannot open."""
    with needs("cv2"):
        import cv2

    p = Path(path)
    if not p.is_file():
        raise ValueError(f"video: no such file {p}")
    cap = cv2.VideoCapture(str(p))
    if not cap.isOpened():
        raise ValueError(f"video: OpenCV cannot open {p}")
    try:
        yield cap
    finally:
        cap.release()


def read_frames(path: Path | str) -> Iterator[np.ndarray]:
    """The frames of a video file, ``(h, w, 3)`` uint8 BGR, in order."""
    with _capture(path) as cap:
        while True:
            ok, img = cap.read()
            if not ok:
                break
            yield img


def video_info(path: Path | str) -> tuple[int, float, tuple[int, int]]:
    """Frame count (as the container says), frames per second and ``(width, height)`` of a video."""
    with needs("cv2"):
        import cv2

    with _capture(path) as cap:
        n = int(cap.get(cv2.CAP_PROP_FRAME_COUNT))
        fps = float(cap.get(cv2.CAP_PROP_FPS)) or 30.0
        size = (int(cap.get(cv2.CAP_PROP_FRAME_WIDTH)), int(cap.get(cv2.CAP_PROP_FRAME_HEIGHT)))
    return n, fps, size


__all__ = ["IMAGE_SUFFIXES", "read_frames", "source_frames", "video_info"]
