"""Node latency: time from reading a detections frame to having published its team state.

Starts ``lookalike serve`` as its own process on loopback, then plays a simulated team in real
time (30 Hz camera, M=10 detections at most, N=7 robots reporting at 10 Hz with the preset's
network) from this process, and prints:

- the node's own figure (``latency_ms`` of its counters: socket read to last ``sendto``), and
- the round trip seen by a subscriber (camera ``sendto`` to the team state's arrival), and
- without sockets, in this process: decode + identify + encode per frame, and the tracker's share.

By default the node sends each team state to every robot and to the subscriber (8 sends a frame);
``--group`` measures the batched send instead: one datagram per frame to a loopback multicast
group that the robots and the subscriber join (``serve --group``). On the shared 2-core machine
the multicast send was the slower of the two (docs/howto/robot-team.md), so the target lines
measure the per-robot replies unless ``--group`` is given.

Target (issue 18): median <= 1 ms, p99 <= 5 ms at 30 Hz with 7 robots (the node's own figure). Both
are printed as wall time (what a subscriber waits; on a loaded machine it includes the waits for a
core) and as the node thread's CPU time per frame (``cpu_ms`` of its counters).

    .venv/bin/python benchmarks/node_latency.py [--tracker kalman_ha2] [--seconds 20] [--group]
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

import numpy as np
from _common import report_target

from lookalike.node import (
    Endpoint,
    IdentifierConfig,
    Status,
    StatusRequest,
    TeamIdentifier,
    TeamState,
    decode,
    encode,
)
from lookalike.node.teamsim import (
    SimClock,
    camera_messages,
    robot_reports,
    run_robot,
    team_sequence,
)
from lookalike.trackers import make_tracker


def in_process(tracker_name: str, sequence) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Per-frame milliseconds of decode + identify + encode (wall), of ``tracker.update`` alone (wall),
    and of decode + identify + encode in this thread's CPU time."""
    n = sequence.config.n_agents
    identifier = TeamIdentifier(make_tracker(tracker_name, n_agents=n), IdentifierConfig(n_robots=n))
    tracker, tracker_ms = identifier.tracker, []
    update = tracker.update

    def timed(frame):
        t0 = time.perf_counter()
        out = update(frame)
        tracker_ms.append((time.perf_counter() - t0) * 1e3)
        return out

    tracker.update = timed
    reports = sorted((item for j in range(n) for item in robot_reports(sequence, j)), key=lambda item: item[0])
    total_ms, cpu_ms, i = [], [], 0
    for data in [encode(m) for m in camera_messages(sequence)]:
        c0 = time.thread_time()
        t0 = time.perf_counter()
        message = decode(data)
        while i < len(reports) and reports[i][0] <= message.time:
            identifier.add_report(reports[i][1])
            i += 1
        _, team = identifier.add_frame(message)
        encode(team)
        total_ms.append((time.perf_counter() - t0) * 1e3)
        cpu_ms.append((time.thread_time() - c0) * 1e3)
    return np.array(total_ms), np.array(tracker_ms), np.array(cpu_ms)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--tracker", default="kalman_ha2")
    parser.add_argument("--preset", default="m10n7")
    parser.add_argument("--seconds", type=float, default=20.0)
    parser.add_argument("--group", action="store_true", help="One multicast send per frame, not per-robot replies.")
    args = parser.parse_args()

    sequence = team_sequence(args.preset, 0, args.seconds)
    n_robots = sequence.config.n_agents
    group = ("239.255.77.1", _free_port()) if args.group else None
    subscriber = Endpoint(("127.0.0.1", 1), group=group)
    fan_out = ["--group", "{}:{}".format(*group)] if group else ["--publish", "{}:{}".format(*subscriber.address)]
    with tempfile.TemporaryDirectory() as tmp:
        port_file = Path(tmp) / "addr"
        node = subprocess.Popen(
            [sys.executable, "-c", "from lookalike.cli import main; main()", "serve", "--tracker", args.tracker,
             "--robots", str(n_robots), "--listen", "127.0.0.1:0", "--port-file", str(port_file),
             *fan_out, "--status-interval", "0", "--log-level", "warning"])
        while not port_file.is_file():
            if node.poll() is not None:
                raise SystemExit("the node did not start")
            time.sleep(0.05)
        host, port = port_file.read_text().strip().rsplit(":", 1)
    address = (host, int(port))

    clock = SimClock(epoch=time.time() + 0.5, speed=1.0)
    robots = [threading.Thread(target=lambda j=j: run_robot(Endpoint(address, group=group), j, sequence, clock,
                                                            linger_s=0.1))
              for j in range(n_robots)]
    sent_at: dict[int, float] = {}
    arrived_at: dict[int, float] = {}

    def camera() -> None:
        with Endpoint(address) as cam:
            for message in camera_messages(sequence):
                clock.wait_until(message.time)
                sent_at[message.frame] = time.perf_counter()
                cam.send(message)

    threads = robots + [threading.Thread(target=camera)]
    for t in threads:
        t.start()
    end = clock.epoch + args.seconds + 1.0
    while time.time() < end:
        message = subscriber.receive(0.05)
        if isinstance(message, TeamState):
            arrived_at.setdefault(message.frame, time.perf_counter())
    for t in threads:
        t.join()
    with Endpoint(address) as client:
        client.send(StatusRequest())
        status = client.receive(2.0)
    node.terminate()
    node.wait(timeout=20)
    if not isinstance(status, Status):
        raise SystemExit("no status from the node")
    lat = status.counters.get("latency_ms", {})
    round_trip = np.array([arrived_at[k] - sent_at[k] for k in arrived_at if k in sent_at]) * 1e3
    print(f"tracker {args.tracker}, preset {args.preset} (N={n_robots}, M={sequence.config.max_detections}), "
          f"{len(sequence)} frames at {sequence.config.frame_rate_hz:g} Hz, "
          f"{'per-robot replies' if group is None else 'one multicast send per frame'}")
    cpu = status.counters.get("cpu_ms", {})
    print(f"node: read frame -> published: median {lat.get('median', float('nan')):.3f} ms, "
          f"p99 {lat.get('p99', float('nan')):.3f} ms over the last {lat.get('frames', 0)} frames (wall time)")
    print(f"node: CPU time of the node thread per frame: median {cpu.get('median', float('nan')):.3f} ms, "
          f"p99 {cpu.get('p99', float('nan')):.3f} ms (the wall time less the waits for a core)")
    print(f"subscriber round trip: median {np.median(round_trip):.3f} ms, p99 {np.percentile(round_trip, 99):.3f} ms "
          f"({round_trip.size} of {len(sequence)} frames received)")
    c = status.counters
    total, tracker, total_cpu = in_process(args.tracker, sequence)
    print(f"in process, no sockets: decode+identify+encode median {np.median(total):.3f} ms, "
          f"p99 {np.percentile(total, 99):.3f} ms (wall; CPU time median {np.median(total_cpu):.3f} ms, "
          f"p99 {np.percentile(total_cpu, 99):.3f} ms); tracker alone median {np.median(tracker):.3f} ms, "
          f"p99 {np.percentile(tracker, 99):.3f} ms (wall)")
    load = os.getloadavg()[0]
    print(f"load average during the run: {load:.1f} on {os.cpu_count()} cores "
          "(wall latency includes waiting for a core)")
    print(f"counters: frames {c['frames']} reports {c['reports']} late {c['late']} published {c['published']} "
          f"rejected {c['rejected_total']}")
    report_target("node median latency (wall)", lat.get("median", float("inf")), 1.0, higher_is_better=False,
                  unit=" ms")
    report_target("node p99 latency (wall)", lat.get("p99", float("inf")), 5.0, higher_is_better=False, unit=" ms")
    report_target("node median CPU time per frame", cpu.get("median", float("inf")), 1.0, higher_is_better=False,
                  unit=" ms")
    report_target("node p99 CPU time per frame", cpu.get("p99", float("inf")), 5.0, higher_is_better=False,
                  unit=" ms")


def _free_port() -> int:
    """A UDP port free on this machine now (for the multicast group)."""
    import socket

    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
        s.bind(("", 0))
        return int(s.getsockname()[1])


if __name__ == "__main__":
    main()
