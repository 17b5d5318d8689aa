"""MOTChallenge tracks drawn on a video or image folder, or world tracks from above (MP4, optional GIF)."""

from __future__ import annotations

from collections.abc import Callable, Iterable, Iterator
from pathlib import Path

import numpy as np

from lookalike._optional import needs
from lookalike.io import MotTable
from lookalike.io.video_frames import source_frames
from lookalike.viz.annotate import (
    Tails,
    draw_box_tracks,
    draw_caption,
    draw_label,
    draw_tail,
)
from lookalike.viz.colors import identity_colour
from lookalike.viz.video import VideoWriter


def overlay_tracks(source: Path | str | Iterable[np.ndarray], tracks: MotTable, output: Path | str, *,
                   gif: Path | str | None = None, tail: int = 25, fps: float | None = None,
                   advance: Callable[[], None] | None = None) -> int:
    """Draw ``tracks`` (1-based frames, ids >= 0) on every frame of ``source`` (a video file, an image folder, or
    the frames themselves, at ``fps`` or 30) into ``output``; returns the count."""
    frames, _, source_fps = source_frames(source) if isinstance(source, (str, Path)) else (iter(source), 0, 30.0)
    keep = np.asarray(tracks.track_id) >= 0
    frame_no = np.asarray(tracks.frame)[keep].astype(int)
    ids = np.asarray(tracks.track_id)[keep].astype(int)
    boxes = np.asarray(tracks.xywh, dtype=float)[keep]
    tails = Tails(length=max(tail, 1))
    count = 0
    with VideoWriter(output, fps=fps or source_fps, gif=gif) as writer:
        for k, image in enumerate(frames):
            img = image.copy()
            sel = frame_no == k + 1
            draw_box_tracks(img, k, ids[sel], boxes[sel], tails)
            draw_caption(img, [f"frame {k + 1}  tracks: {int(sel.sum())}"])
            writer.write(img)
            count += 1
            if advance is not None:
                advance()
    if count == 0:
        raise ValueError(f"video: {source} has no frames")
    return count


def undrawn(tracks: MotTable, frames: int) -> str | None:
    """Why :func:`overlay_tracks` drew some rows of ``tracks`` on ``frames`` frames nowhere (no rows, ids all < 0 as in
    a detection file, rows past the last frame), else None."""
    ids, frame_no = np.asarray(tracks.track_id), np.asarray(tracks.frame)
    if not len(ids):
        return "no rows; nothing was drawn"
    if not (ids >= 0).any():
        return "every id is negative (a detection file?); nothing was drawn"
    past = int(((frame_no > frames) & (ids >= 0)).sum())
    if past:
        last = int(frame_no.max())
        return f"{past} rows of frames {frames + 1}-{last} lie past the video's {frames} frames; not drawn"
    return None


def blank_frames(tracks: MotTable, count: int, margin_px: int = 20) -> Iterator[np.ndarray]:
    """``count`` white BGR frames wide and high enough (even sides) for every box of ``tracks`` (px) plus
    ``margin_px``."""
    right = np.asarray(tracks.xywh)[:, :2] + np.asarray(tracks.xywh)[:, 2:] if len(tracks) else np.zeros((1, 2))
    width, height = (2 * ((max(int(np.ceil(v)), 0) + margin_px + 1) // 2) for v in right.max(axis=0))
    for _ in range(count):
        yield np.full((height, width, 3), 255, np.uint8)


def world_positions(tracks: MotTable) -> np.ndarray:
    """``(n, 2)`` world ``x, y`` (m) of a MOTChallenge table (columns 8 and 9, 1-based); ValueError when absent."""
    extra = np.asarray(tracks.extra, dtype=float)
    if extra.ndim != 2 or extra.shape[1] < 2 or len(extra) == 0:
        raise ValueError("tracks: no world coordinates (MOTChallenge columns 8 and 9 hold world x, y in metres)")
    xy = extra[:, :2]
    if np.all(xy == -1):
        raise ValueError("tracks: world coordinates are all -1 (unset); write x, y in metres in columns 8 and 9")
    return xy


def birdseye_video(tracks: MotTable, output: Path | str, *, size_px: int = 640, fps: float = 30.0,
                   gif: Path | str | None = None, tail: int = 60, advance: Callable[[], None] | None = None) -> int:
    """World tracks from above, one MP4 frame per frame 1..last (a metre grid, dots with tails); returns the count."""
    with needs("cv2"):
        import cv2

    xy = world_positions(tracks)
    frame_no = np.asarray(tracks.frame).astype(int)
    ids = np.asarray(tracks.track_id).astype(int)
    ok = np.isfinite(xy).all(axis=1) & (ids >= 0)
    if not ok.any():
        raise ValueError("tracks: no rows with an id >= 0 and finite world coordinates")
    lo, hi = xy[ok].min(axis=0) - 0.5, xy[ok].max(axis=0) + 0.5
    scale = (size_px - 40) / float(max(hi - lo))

    def px(p: np.ndarray) -> np.ndarray:  # x right, y up
        return np.column_stack([20 + (p[:, 0] - lo[0]) * scale, size_px - 20 - (p[:, 1] - lo[1]) * scale])

    base = np.full((size_px, size_px, 3), 250, np.uint8)
    for gx in np.arange(np.ceil(lo[0]), hi[0] + 1e-9):
        u = int(px(np.array([[gx, lo[1]]]))[0, 0])
        cv2.line(base, (u, 0), (u, size_px), (225, 225, 225), 1)
    for gy in np.arange(np.ceil(lo[1]), hi[1] + 1e-9):
        v = int(px(np.array([[lo[0], gy]]))[0, 1])
        cv2.line(base, (0, v), (size_px, v), (225, 225, 225), 1)
    tails = Tails(length=max(tail, 1))
    count = 0
    with VideoWriter(output, fps=fps, gif=gif) as writer:
        for f in range(1, int(frame_no[ok].max()) + 1):
            sel = ok & (frame_no == f)
            img = base.copy()
            for i, p in zip(ids[sel], px(xy[sel])):
                tails.add(f, int(i), p)
            tails.expire(f, 5)
            for i, pts in tails.items():
                draw_tail(img, pts, identity_colour(i))
            for i, p in zip(ids[sel], px(xy[sel])):
                cv2.circle(img, (round(p[0]), round(p[1])), 6, identity_colour(int(i)), -1, cv2.LINE_AA)
                draw_label(img, f"{int(i)}", (round(p[0]) + 6, round(p[1]) - 6), identity_colour(int(i)))
            draw_caption(img, [f"frame {f}  tracks: {int(sel.sum())}  grid: 1 m"])
            writer.write(img)
            count += 1
            if advance is not None:
                advance()
    return count
