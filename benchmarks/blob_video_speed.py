"""The real-time video command's speed against the video's own frame rate: ``lookalike track --video test_A.avi
--detector blob -t boxtrack --targets 8 --online -o OUT`` (zebrafish, 1160x938, 501 frames at 28 frames/s; the
frame-by-frame closed set, the path a live camera takes), whole process, wall time, once with an empty blob cache
(settings estimated, blobs detected) and once with the cache it filled. The target: frames per second at least the
video's own, on a fresh cache. The default (identities over the whole video, with the learned look) is timed by
``video_identities.py``.

``python benchmarks/blob_video_speed.py [--video PATH]``
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _common import SHARED_DATA, report_target  # noqa: E402


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--video", type=Path, default=SHARED_DATA / "zebrafish" / "test_A.avi")
    args = parser.parse_args()
    if not args.video.is_file():
        print(f"skipped: {args.video} is absent")
        return 0
    import cv2

    cap = cv2.VideoCapture(str(args.video))
    fps, frames = cap.get(cv2.CAP_PROP_FPS), int(cap.get(cv2.CAP_PROP_FRAME_COUNT))
    cap.release()
    with tempfile.TemporaryDirectory() as tmp:
        env = {**os.environ, "LOOKALIKE_CACHE": tmp, "OMP_NUM_THREADS": "1"}
        seconds = {}
        for run in ("fresh cache", "cached"):
            t0 = time.perf_counter()
            subprocess.run([sys.executable, "-m", "lookalike", "track", "--video", str(args.video), "--detector",
                            "blob", "-t", "boxtrack", "--targets", "8", "--online", "-o", str(Path(tmp) / "out.txt")],
                           env=env, check=True, capture_output=True)
            seconds[run] = time.perf_counter() - t0
            print(f"{args.video.name}, {run}: {seconds[run]:.1f} s wall, {frames / seconds[run]:.0f} frames/s",
                  flush=True)
    passed = report_target(f"blob video tracking on a fresh cache, frames/s (the video's own: {fps:g})",
                           frames / seconds["fresh cache"], fps)
    return 0 if passed else 1


if __name__ == "__main__":
    sys.exit(main())
