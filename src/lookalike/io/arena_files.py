"""A rendered arena (:mod:`lookalike.sim.arena_render`) written as a video with its truth, ready for
``lookalike track --video`` and ``lookalike eval``."""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

from lookalike._optional import needs
from lookalike.io.motchallenge import write_mot
from lookalike.io.outputs import atomic_path, write_atomic
from lookalike.sim.arena import ArenaConfig
from lookalike.sim.arena_render import Arena, simulate_arena
from lookalike.types.mot_table import detection_rows


@dataclass(frozen=True)
class ArenaFiles:
    """What :func:`write_arena` wrote: ``video`` (``arena.avi``, Motion-JPEG), ``gt`` (``gt.txt``, MOTChallenge
    rows: 1-based frame, id 1..N, the silhouette's axis-aligned box in px, conf 1) and ``points`` (``points.csv``,
    ``frame,id,x,y``: 1-based frame, id, the silhouette's centroid in px), and the ``arena`` itself."""

    video: Path
    gt: Path
    points: Path
    arena: Arena


def write_arena(folder: str | os.PathLike[str], config: ArenaConfig | None = None, seed: int = 0) -> ArenaFiles:
    """Simulate an arena of ``config`` with ``seed`` and write its three files into ``folder`` (made if needed)."""
    with needs("cv2"):
        import cv2

    arena = simulate_arena(config, seed)
    cfg, out = arena.config, Path(folder)
    out.mkdir(parents=True, exist_ok=True)
    video = out / "arena.avi"
    with atomic_path(video) as tmp:
        writer = cv2.VideoWriter(str(tmp), cv2.VideoWriter.fourcc(*"MJPG"), cfg.frame_rate_hz,
                                 (cfg.image_px, cfg.image_px))
        if not writer.isOpened():
            raise OSError(f"{video}: OpenCV cannot write Motion-JPEG video here")
        try:
            for image in arena.frames():
                writer.write(image)
        finally:
            writer.release()
    rows = detection_rows(arena.truth[:, 0], arena.boxes(), 1.0)
    rows[:, 1] = arena.truth[:, 1]
    gt = write_mot(out / "gt.txt", rows)
    lines = ["frame,id,x,y\n"] + [f"{int(f)},{int(i)},{x:.3f},{y:.3f}\n" for f, i, x, y in arena.truth[:, :4]]
    points = write_atomic(out / "points.csv", "".join(lines))
    return ArenaFiles(video, gt, points, arena)


__all__ = ["ArenaFiles", "write_arena"]
