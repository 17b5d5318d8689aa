"""The blob video pipeline's speed (issue 45): ``lookalike track --video V --detector blob -t boxtrack --targets N
--online -o OUT`` as a whole process on one core, once with an empty blob cache (settings estimated, blobs detected)
and once warm (the cache it filled), in frames per second of CPU time (user + system of the process,
``resource.getrusage(RUSAGE_CHILDREN)``) and of wall time. Videos: test_A (zebrafish, 1160x938, 501 frames at 28
frames/s, N = 8; targets >= 120 frames/s and the video's own frame rate) and the HexBug clip training010 (1080x1226,
101 frames, N = 3 bugs in its CSV; target >= 60 frames/s). The default command (identities over the whole video, with
the learned look; without ``--online``) is timed too, for information. Printed beside them: the CPU time of decoding
the video alone and of starting the command (``lookalike track --help``), the floor under every run. One core:
``OMP_NUM_THREADS=1`` and ``OPENCV_FOR_THREADS_NUM=1`` in the command's environment, ``cv2.setNumThreads(1)`` here.

``python benchmarks/blob_video_speed.py [--video PATH] [--hexbug PATH] [--no-default]``
"""

from __future__ import annotations

import argparse
import os
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _common import SHARED_DATA, report_target  # noqa: E402

ONE_CORE = {"OMP_NUM_THREADS": "1", "OPENBLAS_NUM_THREADS": "1", "MKL_NUM_THREADS": "1", "NUMBA_NUM_THREADS": "1",
            "OPENCV_FOR_THREADS_NUM": "1"}


def child_cpu() -> float:
    """CPU seconds (user + system) of every finished child process so far."""
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def timed(command: list[str], env: dict[str, str]) -> tuple[float, float]:
    """``(CPU s, wall s)`` of running ``command`` to its end."""
    cpu0, wall0 = child_cpu(), time.perf_counter()
    subprocess.run(command, env=env, check=True, capture_output=True)
    return child_cpu() - cpu0, time.perf_counter() - wall0


def decode(video: Path) -> tuple[int, float, float]:
    """``(frames, fps, CPU s)`` of decoding ``video`` once to BGR frames on one thread."""
    import cv2

    cv2.setNumThreads(1)
    cap = cv2.VideoCapture(str(video))
    fps, frames = cap.get(cv2.CAP_PROP_FPS), 0
    t0 = time.process_time()
    while cap.read()[0]:
        frames += 1
    seconds = time.process_time() - t0
    cap.release()
    return frames, fps, seconds


def track_runs(video: Path, targets: int, extra: list[str], label: str, env: dict[str, str],
               frames: int, decode_s: float) -> dict[str, float]:
    """Frames/s of CPU time on a fresh cache and warm, each run printed."""
    rates = {}
    with tempfile.TemporaryDirectory() as tmp:
        command = [sys.executable, "-m", "lookalike", "track", "--video", str(video), "--detector", "blob", "-t",
                   "boxtrack", "--targets", str(targets), *extra, "-o", str(Path(tmp) / "out.txt")]
        for run in ("fresh cache", "warm"):
            cpu, wall = timed(command, {**env, "LOOKALIKE_CACHE": tmp})
            rates[run] = frames / cpu
            share = f"; decoding once is {100 * decode_s / cpu:.0f}% of its CPU" if run == "fresh cache" else ""
            print(f"{video.name} {label}, {run}: {cpu:.2f} s CPU ({frames / cpu:.0f} frames/s), {wall:.2f} s wall "
                  f"({frames / wall:.0f} frames/s){share}", flush=True)
    return rates


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--video", type=Path, default=SHARED_DATA / "zebrafish" / "test_A.avi")
    parser.add_argument("--hexbug", type=Path, default=SHARED_DATA / "hexbug" / "training010.mp4")
    parser.add_argument("--no-default", action="store_true", help="skip the default (offline) command")
    args = parser.parse_args()
    if not args.video.is_file():
        print(f"skipped: {args.video} is absent")
        return 0
    env = {**os.environ, **ONE_CORE}
    start, _ = timed([sys.executable, "-m", "lookalike", "track", "--help"], env)
    print(f"starting the command (lookalike track --help): {start:.2f} s CPU", flush=True)
    passed = True
    clips = [(args.video, 8, 120.0)] + ([(args.hexbug, 3, 60.0)] if args.hexbug.is_file() else [])
    if not args.hexbug.is_file():
        print(f"HexBug clip skipped: {args.hexbug} is absent")
    for video, targets, target in clips:
        frames, fps, decode_s = decode(video)
        print(f"{video.name}: {frames} frames at {fps:g} frames/s; decoding alone {decode_s:.2f} s CPU "
              f"({frames / decode_s:.0f} frames/s)", flush=True)
        online = track_runs(video, targets, ["--online"], "--online", env, frames, decode_s)
        if not args.no_default and video == args.video:
            track_runs(video, targets, [], "default (offline, for information)", env, frames, decode_s)
        for run in ("fresh cache", "warm"):
            passed &= report_target(f"blob pipeline on {video.name} (--online --targets {targets}), {run}, "
                                    "frames/s of CPU on one core", online[run], target)
        if video == args.video:
            passed &= report_target(f"blob pipeline on {video.name} on a fresh cache, frames/s of CPU (the video's "
                                    f"own: {fps:g})", online["fresh cache"], fps)
    return 0 if passed else 1


if __name__ == "__main__":
    sys.exit(main())
