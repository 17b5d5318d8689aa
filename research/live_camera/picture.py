"""The picture of docs/howto/live-camera.md: the test scene of tests/test_live.py served as an MJPEG stream on
127.0.0.1, tracked live (blob detector, boxtrack), and one late frame drawn with its identities and tails.

Run from the repository root: ``.venv/bin/python research/live_camera/picture.py [docs/images/live-camera.png]``."""

from __future__ import annotations

import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT))  # the scene and the server are the test's (tests/test_live.py)

import cv2  # noqa: E402
import numpy as np  # noqa: E402

from lookalike.io.live import prepare_live, track_live  # noqa: E402
from lookalike.io.sources import open_live  # noqa: E402
from lookalike.trackers import make_tracker  # noqa: E402
from lookalike.viz.annotate import Tails, draw_box_tracks, draw_caption  # noqa: E402
from tests.test_live import MjpegServer, scene_frame  # noqa: E402

SCALE = 2  # the 320x240 scene drawn at 640x480


def main(out: Path) -> None:
    server = MjpegServer(150)
    try:
        with tempfile.TemporaryDirectory() as tmp, open_live(server.url) as source:
            plan = prepare_live(source, "blob", make_tracker("boxtrack"), "boxtrack")
            result = Path(tmp) / "live.txt"
            run = track_live(source, plan, result)
            rows = np.loadtxt(result, delimiter=",", ndmin=2)
    finally:
        server.close()
    last = int(rows[:, 0].max())
    image = cv2.resize(scene_frame(last - 1), None, fx=SCALE, fy=SCALE, interpolation=cv2.INTER_NEAREST)
    tails = Tails(length=40)
    frames = np.unique(rows[:, 0])[-40:]  # the tails: the last 40 frames tracked (numbered in turn: no breaks
    for k, frame in enumerate(frames):    # at the frames dropped between them)
        shown = rows[rows[:, 0] == frame]
        canvas = image if frame == last else image.copy()
        draw_box_tracks(canvas, k, shown[:, 1], shown[:, 2:6] * SCALE, tails, max_gap=40)
    draw_caption(image, [f"live MJPEG stream, frame {last}: {len(np.unique(rows[:, 1]))} identities",
                         f"{run.frames} frames tracked, {run.dropped} of {run.delivered} dropped while busy"])
    out.parent.mkdir(parents=True, exist_ok=True)
    cv2.imwrite(str(out), image)
    print(f"wrote {out} (frame {last}; {run.frames} frames, {run.dropped} dropped)")


if __name__ == "__main__":
    main(Path(sys.argv[1]) if len(sys.argv) > 1 else ROOT / "docs" / "images" / "live-camera.png")
