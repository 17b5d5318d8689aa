"""Overlaying MOTChallenge tracking results on a video or an image folder (MP4 out, optional GIF)."""

from __future__ import annotations

from collections.abc import Callable, Iterator
from pathlib import Path

import numpy as np

from lookalike.io import MotTable
from lookalike.viz.annotate import Tails, draw_box_tracks, draw_caption
from lookalike.viz.video import VideoWriter, read_frames, video_info

IMAGE_SUFFIXES = (".jpg", ".jpeg", ".png", ".bmp")


def source_frames(source: Path | str) -> tuple[Iterator[np.ndarray], int, float]:
    """Frames of a video file or of a folder of images (sorted by name; a MOTChallenge ``img1``),
    with the frame count and the frame rate (30 for image folders)."""
    import cv2

    p = Path(source)
    if p.is_dir():
        paths = sorted(q for q in p.iterdir() if q.suffix.lower() in IMAGE_SUFFIXES)
        if not paths:
            raise ValueError(f"video: folder {p} holds no images ({', '.join(IMAGE_SUFFIXES)})")

        def images() -> Iterator[np.ndarray]:
            for q in paths:
                img = cv2.imread(str(q), cv2.IMREAD_COLOR)
                if img is None:
                    raise ValueError(f"video: cannot read image {q}")
                yield img

        return images(), len(paths), 30.0
    n, fps, _ = video_info(p)
    return read_frames(p), n, fps


def overlay_tracks(source: Path | str, tracks: MotTable, output: Path | str, *, gif: Path | str | None = None,
                   tail: int = 25, fps: float | None = None,
                   advance: Callable[[], None] | None = None) -> int:
    """Draw ``tracks`` (1-based frames) on every frame of ``source`` and write ``output`` (MP4);
    returns the number of frames written (the input's). Rows with an id < 0 are ignored."""
    frames, _, source_fps = source_frames(source)
    rows_by_frame: dict[int, np.ndarray] = {}
    keep = np.asarray(tracks.track_id) >= 0
    frame_no = np.asarray(tracks.frame)[keep].astype(int)
    order = np.argsort(frame_no, kind="stable")
    ids = np.asarray(tracks.track_id)[keep].astype(int)[order]
    boxes = np.asarray(tracks.xywh, dtype=float)[keep][order]
    frame_no = frame_no[order]
    starts = np.searchsorted(frame_no, np.unique(frame_no))
    for s, e in zip(starts, list(starts[1:]) + [len(frame_no)]):
        rows_by_frame[int(frame_no[s])] = np.arange(s, e)
    tails = Tails(length=max(tail, 1))
    count = 0
    with VideoWriter(output, fps=fps or source_fps, gif=gif) as writer:
        for k, image in enumerate(frames):
            img = image.copy()
            sel = rows_by_frame.get(k + 1, np.zeros(0, dtype=int))
            draw_box_tracks(img, k, ids[sel], boxes[sel], tails)
            draw_caption(img, [f"frame {k + 1}  tracks: {len(sel)}"])
            writer.write(img)
            count += 1
            if advance is not None:
                advance()
    if count == 0:
        raise ValueError(f"video: {source} has no frames")
    return count
