"""Live input for ``lookalike track``: an MJPEG stream served on 127.0.0.1 by the test, a simulated camera (a file
replayed at its frame rate, dropping frames a slow consumer cannot take), and a stop by signal or interrupt that
leaves a complete result file."""

from __future__ import annotations

import dataclasses
import http.server
import os
import signal
import socketserver
import subprocess
import sys
import threading
import time
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

cv2 = pytest.importorskip("cv2")

from lookalike.cli import app  # noqa: E402
from lookalike.io import read_mot  # noqa: E402
from lookalike.io.live import LivePlan, LiveStop, prepare_live, track_live  # noqa: E402
from lookalike.io.sources import LiveSource, is_live, open_live, replay_camera  # noqa: E402
from lookalike.trackers import make_tracker  # noqa: E402

runner = CliRunner()

SIZE = (320, 240)  # width, height px
RATE = 30.0  # frames/s of the scene
# (start x, lane y, speed px/frame): three dark discs, each in its own horizontal lane, bouncing off the walls
DISCS = ((40, 50, 3.0), (200, 120, -2.5), (100, 190, 2.0))


def scene_frame(k: int) -> np.ndarray:
    """Frame ``k`` of the test scene: three dark discs on a bright, slightly noisy floor (BGR uint8)."""
    rng = np.random.default_rng(k)
    img = np.clip(rng.normal(200, 2.0, (SIZE[1], SIZE[0], 3)), 0, 255).astype(np.uint8)
    for x0, y, v in DISCS:
        span = SIZE[0] - 40
        x = (x0 - 20 + v * k) % (2 * span)
        x = 20 + (x if x < span else 2 * span - x)
        cv2.circle(img, (int(x), int(y)), 9, (40, 40, 40), -1)
    return img


def write_scene(path: Path, frames: int) -> Path:
    """The scene as an MJPG video file of ``frames`` frames at :data:`RATE`."""
    writer = cv2.VideoWriter(str(path), cv2.VideoWriter_fourcc(*"MJPG"), RATE, SIZE)
    assert writer.isOpened()
    for k in range(frames):
        writer.write(scene_frame(k))
    writer.release()
    return path


class MjpegServer:
    """An MJPEG stream (``multipart/x-mixed-replace``) of the scene on 127.0.0.1 at :data:`RATE`; each client gets
    frames from 0, ``frames`` of them (None: without end)."""

    def __init__(self, frames: int | None) -> None:
        jpegs = [cv2.imencode(".jpg", scene_frame(k), [cv2.IMWRITE_JPEG_QUALITY, 90])[1].tobytes()
                 for k in range(frames or 300)]

        class Handler(http.server.BaseHTTPRequestHandler):
            def do_GET(self) -> None:  # noqa: N802 (http.server's name)
                self.send_response(200)
                self.send_header("Content-Type", "multipart/x-mixed-replace; boundary=frame")
                self.end_headers()
                k, due = 0, time.monotonic()
                try:
                    while frames is None or k < frames:
                        data = jpegs[k % len(jpegs)]
                        self.wfile.write(b"--frame\r\nContent-Type: image/jpeg\r\nContent-Length: %d\r\n\r\n"
                                         % len(data) + data + b"\r\n")
                        k, due = k + 1, due + 1 / RATE
                        time.sleep(max(due - time.monotonic(), 0.0))
                except (BrokenPipeError, ConnectionResetError):
                    pass

            def log_message(self, *args: object) -> None:
                pass

        self.server = socketserver.ThreadingTCPServer(("127.0.0.1", 0), Handler)
        self.server.daemon_threads = True
        self.url = f"http://127.0.0.1:{self.server.server_address[1]}/stream.mjpg"
        threading.Thread(target=self.server.serve_forever, daemon=True).start()

    def close(self) -> None:
        self.server.shutdown()
        self.server.server_close()


@pytest.fixture
def stream() -> Iterator[MjpegServer]:
    """A 4 s stream (120 frames); skipped when OpenCV cannot read it here."""
    server = MjpegServer(120)
    try:
        probe = cv2.VideoCapture(server.url, cv2.CAP_FFMPEG)
        ok = probe.isOpened() and probe.read()[0]
        probe.release()
        if not ok:
            pytest.skip("this OpenCV build cannot read an MJPEG stream over HTTP (no FFmpeg backend?)")
        yield server
    finally:
        server.close()


def _lanes(rows: np.ndarray) -> dict[int, float]:
    """Each identity's spread of box-centre heights (px): a few px when it stayed in one disc's lane."""
    cy = rows[:, 3] + rows[:, 5] / 2
    return {int(i): float(np.ptp(cy[rows[:, 1] == i])) for i in np.unique(rows[:, 1])}


def test_is_live_tells_cameras_and_urls_from_files(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert is_live("0") and is_live("rtsp://cam.local/stream") and is_live("http://127.0.0.1:8080/x.mjpg")
    assert not is_live("clip.mp4") and not is_live(None)
    (tmp_path / "1").write_bytes(b"")
    assert not is_live("1")  # a file named 1 here is a file
    with pytest.raises(ValueError, match="cannot open"):
        open_live("http://127.0.0.1:9/nothing.mjpg")  # (port 9: nothing listens)


def test_served_mjpeg_stream_is_tracked_with_stable_identities(stream, tmp_path):
    out = tmp_path / "live.txt"
    result = runner.invoke(app, ["track", "--video", stream.url, "--detector", "blob", "-t", "boxtrack",
                                 "-o", str(out)])
    assert result.exit_code == 0, result.output
    assert "dropped while busy" in result.output and "stopped: end of stream" in result.output
    assert "inferred 3 targets" in result.output
    table = np.loadtxt(out, delimiter=",", ndmin=2)
    assert len(table) > 100
    lanes = _lanes(table)
    assert len(lanes) == 3, lanes  # three identities, one per disc, all along
    assert max(lanes.values()) < 10, lanes
    assert len(read_mot(out)) == len(table)  # a valid MOTChallenge file


def test_slow_consumer_of_a_simulated_camera_gets_drops_counted(tmp_path):
    clip = write_scene(tmp_path / "scene.avi", 60)
    with replay_camera(clip, speed=2.0) as camera:  # 60 frames/s
        taken = []
        for frame in camera:
            taken.append(frame.number)
            time.sleep(0.05)  # a consumer of 20 frames/s
    assert camera.delivered == 60
    assert camera.dropped > 0
    assert camera.taken == len(taken) and camera.taken + camera.dropped == camera.delivered
    assert taken == sorted(taken) and len(set(taken)) == len(taken)


def test_slow_tracker_on_a_simulated_camera_writes_gaps_not_lag(tmp_path):
    clip = write_scene(tmp_path / "scene.avi", 90)
    tracker = make_tracker("boxtrack", max_targets=3)
    out = tmp_path / "t.txt"
    with replay_camera(clip) as camera:
        plan = prepare_live(camera, "blob", tracker, "boxtrack", n_targets=3)

        def slow(image):
            time.sleep(0.1)  # three frame periods
            return plan.detector(image)

        run = track_live(camera, dataclasses.replace(plan, detector=slow), out)
    assert run.dropped > 0 and run.frames + run.dropped == run.delivered == 90
    assert run.clock == "stream" and run.stopped == "end of stream"
    frames = np.unique(np.loadtxt(out, delimiter=",", ndmin=2)[:, 0])
    assert frames.max() <= 90 and (np.diff(frames) > 1).any()  # the dropped frames are gaps in the numbering


def _source(images: list[np.ndarray], rate: float = RATE) -> LiveSource:
    """A source handing ``images`` as fast as taken (waits for the consumer: nothing dropped)."""
    pending = iter(images)
    gate = threading.Semaphore(1)
    count, closing = [0], [False]

    def read():
        gate.acquire()
        image = None if closing[0] else next(pending, None)
        count[0] += 1
        return None if image is None else (image, (count[0] - 1) / rate)

    source = LiveSource(read, "frames", rate)
    source._gate = gate  # released by each take below
    original = source.next

    def take(timeout=None):
        frame = original(timeout)
        if frame is not None:
            gate.release()
        return frame

    def close():  # a reader waiting for a take ends at once (a camera's read returns within a frame)
        closing[0] = True
        gate.release()
        original_close()

    source.next, original_close, source.close = take, source.close, close
    return source


@pytest.mark.parametrize("how", ["KeyboardInterrupt", "SIGTERM", "max_frames", "seconds"])
def test_a_stop_mid_run_leaves_a_complete_result_file(tmp_path, how):
    images = [scene_frame(k) for k in range(200)]
    out = tmp_path / "t.txt"
    out.write_text("old\n")
    with _source(images) as source, LiveStop() as stop:
        plan = prepare_live(source, "blob", make_tracker("boxtrack"), "boxtrack", n_targets=3, stop=stop)

        def on_frame(run):
            assert out.read_text() == "old\n"  # the result appears only whole
            if run.frames == 70 and how == "KeyboardInterrupt":
                raise KeyboardInterrupt
            if run.frames == 70 and how == "SIGTERM":
                os.kill(os.getpid(), signal.SIGTERM)

        run = track_live(source, plan, out, stop=stop, on_frame=on_frame,
                         max_frames=90 if how == "max_frames" else None, seconds=3.0 if how == "seconds" else None)
    table = np.loadtxt(out, delimiter=",", ndmin=2)
    expected = {"KeyboardInterrupt": 70, "SIGTERM": 70, "max_frames": 90, "seconds": 91}[how]
    assert run.frames == expected, run.stopped
    assert table[:, 0].max() == expected  # every frame tracked is in the file, up to the last one
    assert len(np.unique(table[:, 1])) == 3
    assert run.stopped == {"KeyboardInterrupt": "KeyboardInterrupt", "SIGTERM": "SIGTERM", "max_frames": "90 frames",
                           "seconds": "3 s"}[how]
    assert [p.name for p in tmp_path.iterdir()] == ["t.txt"]  # no temporary file left


def test_sigterm_to_the_command_leaves_a_complete_result_file(tmp_path):
    server = MjpegServer(None)  # a stream without end
    out = tmp_path / "live.txt"
    try:
        proc = subprocess.Popen([sys.executable, "-m", "lookalike", "track", "--video", server.url, "--detector",
                                 "blob", "-t", "sort", "-o", str(out)], stdout=subprocess.PIPE,
                                stderr=subprocess.STDOUT, text=True, env={**os.environ, "COLUMNS": "200"})
        deadline = time.monotonic() + 120
        while time.monotonic() < deadline and proc.poll() is None:  # until rows reach the temporary file
            if any(p.name != "live.txt" and p.stat().st_size > 0 for p in tmp_path.iterdir()):
                break
            time.sleep(0.2)
        if proc.poll() is not None:
            pytest.skip(f"the command ended before tracking: {proc.communicate()[0][-400:]}")
        time.sleep(0.5)
        proc.send_signal(signal.SIGTERM)
        output, _ = proc.communicate(timeout=60)
    finally:
        server.close()
    assert proc.returncode == 0, output
    assert "stopped: SIGTERM" in output
    table = np.loadtxt(out, delimiter=",", ndmin=2)
    assert len(table) > 0 and table.shape[1] == 10
    assert [p.name for p in tmp_path.iterdir()] == ["live.txt"]


def test_live_source_refuses_what_needs_a_file(tmp_path):
    result = runner.invoke(app, ["track", "--video", "http://127.0.0.1:9/x", "-o", str(tmp_path / "t.txt")])
    assert result.exit_code == 2 and "needs --detector" in result.output
    result = runner.invoke(app, ["track", "--video", "http://127.0.0.1:9/x", "--detector", "blob", "-t", "boxtrack",
                                 "--annotate", str(tmp_path / "a.mp4"), "-o", str(tmp_path / "t.txt")])
    assert result.exit_code == 2 and "--annotate" in result.output
    result = runner.invoke(app, ["track", "--video", "clip.mp4", "--detector", "blob", "--seconds", "3",
                                 "-o", str(tmp_path / "t.txt")])
    assert result.exit_code == 2 and "only with a live --video" in result.output


def test_served_stream_with_an_onnx_detector_stops_after_max_frames(stream, tmp_path):
    pytest.importorskip("onnx")
    pytest.importorskip("onnxruntime")
    from tests.test_onnx_detector import _darkness_grid_model  # a tiny model finding dark cells

    model = _darkness_grid_model(tmp_path / "dark.onnx")
    out = tmp_path / "live.txt"
    result = runner.invoke(app, ["track", "--video", stream.url, "--detector", str(model), "--blob", "score=0.05",
                                 "-t", "sort", "--max-frames", "40", "-o", str(out)])
    assert result.exit_code == 0, result.output
    assert "stopped: 40 frames" in result.output
    table = np.loadtxt(out, delimiter=",", ndmin=2)
    assert len(table) > 0 and len(np.unique(table[:, 0])) <= 40


def test_a_source_without_stamps_is_timed_by_the_wall_clock_on_its_frame_period():
    images = iter([scene_frame(k) for k in range(12)])

    def read():
        time.sleep(0.02)
        image = next(images, None)
        return None if image is None else (image, None)

    with LiveSource(read, "unstamped", frame_rate=50.0) as source:
        times = [f.time for f in source]
    assert source.clock == "wall clock" and len(times) + source.dropped == 12
    assert times == sorted(times) and times[-1] > 0
    assert np.allclose(np.asarray(times) * 50, np.round(np.asarray(times) * 50))  # whole frame periods


def test_stream_stamps_that_leave_the_wall_clock_give_way_to_it():
    """An MJPEG stream through FFmpeg is stamped at an invented 25 frames/s: at 10 real frames a second its stamps
    run at 0.4x real time. After STAMP_CHECK_S of a live source the wall clock takes over, without a jump; stamps
    that keep to the wall clock (and any stamps of a source not live) are kept."""
    from lookalike.io.sources import STAMP_CHECK_S

    def run(stamp_period: float, realtime: bool) -> tuple[list[float], str]:
        wall = [0.0]
        images = iter([scene_frame(k % 4) for k in range(60)])
        count = [0]

        def read():
            image = next(images, None)
            if image is None:
                return None
            wall[0] += 0.1  # 10 frames a second of real time
            count[0] += 1
            return image, count[0] * stamp_period

        source = LiveSource(read, "mjpeg", 25.0, realtime=realtime, now=lambda: wall[0])
        times = []
        while (frame := source.next(timeout=5.0)) is not None:
            times.append(frame.time)
        source.close()
        return times, source.clock

    times, clock = run(0.04, realtime=True)
    assert clock == "wall clock (the stream's stamps ran at 0.40× real time)"
    # (frames replaced before they were taken are dropped, but the last one is always taken): 2.4 s of stamps would
    # end at 2.36; the wall clock from the switch (2 s in, at the stamps' 0.76 s) ends at 0.76 + 5.9 - 2.0
    assert times == sorted(times) and 4.55 < times[-1] < 4.7 and STAMP_CHECK_S == 2.0
    kept, clock = run(0.1, realtime=True)
    assert clock == "stream" and kept[-1] == pytest.approx(5.9)
    assert run(0.04, realtime=False)[1] == "stream"


def test_a_live_closed_set_of_blobs_learns_the_look_and_keeps_each_disc_in_its_lane(tmp_path):
    from lookalike.trackers.offline.online_look import LookIdentities

    out = tmp_path / "t.txt"
    source = _source([scene_frame(k) for k in range(120)])
    plan = prepare_live(source, "blob", make_tracker("boxtrack"), "boxtrack", n_targets=3)
    assert isinstance(plan.tracker, LookIdentities) and plan.tracker.frame_rate == RATE
    run = track_live(source, plan, out)
    assert run.frames == 120 and plan.tracker.looks.frame == 120
    assert max(len(p.shapes) for p in plan.tracker.looks.pieces.values()) > 8  # shapes came after the sample
    rows = np.loadtxt(out, delimiter=",", ndmin=2)
    assert set(np.unique(rows[:, 1]).astype(int)) == {1, 2, 3} and max(_lanes(rows).values()) < 5


def _plan_without_detections() -> LivePlan:
    """A plan of no sample that finds nothing in any frame (the stops need no detector)."""
    from lookalike.types import Detections

    return LivePlan(lambda image: Detections.empty(), make_tracker("sort"))


def _stalling(frames: int, signal: str) -> tuple[LiveSource, LiveStop, threading.Event]:
    """A live source that sends ``frames`` frames, then stalls (no frame, no end) until the returned event is set,
    and a stop that ``signal`` sets while the consumer waits on the stall."""
    stalled, resume = threading.Event(), threading.Event()
    count = [0]

    def read():
        if count[0] == frames:
            stalled.set()
            resume.wait(10.0)  # (the test ends the stall when it is done)
            return None
        count[0] += 1
        return scene_frame(count[0]), count[0] / RATE

    stop = LiveStop()
    source = LiveSource(read, "stalling", RATE)
    original = source.next

    def take(timeout=None):
        if stalled.is_set():
            stop.set(signal)
        return original(timeout)

    source.next = take
    return source, stop, resume


def test_a_stop_while_the_source_stalls_ends_the_run_without_waiting_for_a_frame(tmp_path):
    """A stream that stalls (no frame, no end) is stopped by Ctrl-C/SIGTERM at once: it waited for the next frame,
    longer than ``docker stop`` waits before it kills (the file then left unfinished)."""
    source, stop, resume = _stalling(5, "SIGTERM")
    out = tmp_path / "t.txt"
    try:
        run = track_live(source, _plan_without_detections(), out, stop=stop)
        assert run.stopped == "SIGTERM" and 1 <= run.frames <= 5 and out.exists()
    finally:
        resume.set()
        source.close()


def test_a_frame_the_detector_refuses_ends_the_run_keeping_the_frames_tracked(tmp_path):
    """A source whose frames change size after the blob background was fitted: the run ends on that frame, saying
    why, and the result file holds every frame before it (it was deleted, the error raised)."""
    bigger = [cv2.resize(scene_frame(80), (400, 300))]  # (the source ends after it: its reader is not left waiting)
    out = tmp_path / "t.txt"
    with _source([scene_frame(k) for k in range(80)] + bigger) as source:
        plan = prepare_live(source, "blob", make_tracker("boxtrack"), "boxtrack", n_targets=3)
        run = track_live(source, plan, out)
    assert run.frames == 80 and run.stopped.startswith("error: image: shape (300, 400) differs")
    assert np.loadtxt(out, delimiter=",", ndmin=2)[:, 0].max() == 80
    assert [p.name for p in tmp_path.iterdir()] == ["t.txt"]


def test_the_command_exits_1_when_an_error_ends_the_live_run(tmp_path, monkeypatch):
    """The same refused frame through `track`: the result line, then an error naming the file that keeps the frames
    tracked before, and exit status 1 (it was 0, so a script could not tell)."""
    import lookalike.io.sources as sources

    bigger = [cv2.resize(scene_frame(80), (400, 300))]
    monkeypatch.setattr(sources, "open_live", lambda spec: _source([scene_frame(k) for k in range(80)] + bigger))
    out = tmp_path / "t.txt"
    result = runner.invoke(app, ["track", "--video", "0", "--detector", "blob", "-t", "boxtrack", "--targets", "3",
                                 "-o", str(out)])
    assert result.exit_code == 1, result.output
    assert "stopped: error: image: shape (300, 400)" in result.output
    assert "stopped on an error (image: shape" in result.output and "holds every frame tracked" in result.output
    assert np.loadtxt(out, delimiter=",", ndmin=2)[:, 0].max() == 80


def test_a_setup_cut_short_says_what_cut_it(tmp_path):
    """A stop (Ctrl-C, SIGTERM), an error or the end of the source within the first frames leaves too few frames to
    set the blob detector: the error says so (it blamed the scene: 'is the camera static ...?')."""
    frames = iter([(scene_frame(k), k / RATE) for k in range(5)])
    with LiveSource(lambda: next(frames, None), "frames", RATE) as source, LiveStop() as stop:
        stop.set("SIGTERM")
        with pytest.raises(ValueError, match=r"stopped \(SIGTERM\) after 0 frame\(s\) of the first 2 s"):
            prepare_live(source, "blob", make_tracker("boxtrack"), "boxtrack", stop=stop)
    with _source([scene_frame(0)]) as source:
        with pytest.raises(ValueError, match=r"the source ended after 1 frame\(s\)"):
            prepare_live(source, "blob", make_tracker("boxtrack"), "boxtrack")

    def failing():
        raise OSError("camera unplugged")

    with LiveSource(failing, "unplugged", RATE) as source:
        with pytest.raises(ValueError, match=r"the source failed \(camera unplugged\) after 0 frame\(s\)"):
            prepare_live(source, "blob", make_tracker("boxtrack"), "boxtrack")


def test_closing_a_stalled_source_does_not_release_it_under_a_read(monkeypatch):
    """OpenCV's capture is not made to be released while another thread reads it: a source closed while its read
    hangs (a stalled stream) is released by the reader once the read returns, not under it."""
    stalled, resume = threading.Event(), threading.Event()
    reading, released_while_reading = [False], []

    def read():
        reading[0] = True
        stalled.set()
        resume.wait(10.0)
        reading[0] = False
        return None

    def release():
        released_while_reading.append(reading[0])

    real_join = threading.Thread.join
    monkeypatch.setattr(threading.Thread, "join", lambda self, timeout=None: real_join(self, 0.0))  # no 5 s wait
    source = LiveSource(read, "stalled", RATE, release)
    assert stalled.wait(10.0)
    source.close()
    assert released_while_reading == []  # not yet: the read is under way
    resume.set()
    real_join(source._thread, 10.0)
    assert released_while_reading == [False]  # once, after the read


def test_a_stop_while_the_source_stalls_in_the_first_frames_ends_the_sample():
    """Ctrl-C/SIGTERM while the first frames are read from a stalled source ends the sample at once, the read still
    hanging (it waited for the next frame or the source's end)."""
    from lookalike.io.live import sample_frames

    source, stop, resume = _stalling(3, "SIGINT")
    try:
        frames = sample_frames(source, stop=stop)
        assert not source.ended and 1 <= len(frames) <= 3  # back while the read still hangs
    finally:
        resume.set()
        source.close()
