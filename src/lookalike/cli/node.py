"""``lookalike serve`` (the observer node), ``lookalike robot-sim`` and ``lookalike camera-sim``."""

from __future__ import annotations

import json
import logging
import math
import sys
import time
from pathlib import Path
from typing import Any

import typer

from lookalike.cli.app import app, check_outputs_or_fail, check_teams, fail, failing
from lookalike.cli.track import build_tracker
from lookalike.io.outputs import write_atomic
from lookalike.io.sources import SignalStop
from lookalike.node import Endpoint, IdentifierConfig, NodeConfig, NodeServer, TeamState, log_event, parse_address
from lookalike.node.client import resolve_destination
from lookalike.node.messages import MAX_ROBOTS
from lookalike.node.server import check_group, dds_node
from lookalike.node.teamsim import SimClock, camera_messages, run_camera, run_robot, team_sequence
from lookalike.sim.presets import PRESET_NAMES, TEAM_HELP, team_size
from lookalike.trackers import tracker_parameters


def _logger(level: str) -> logging.Logger:
    """The node's logger: one JSON object per line on stderr, with a time stamp and level."""
    numeric = logging.getLevelName(level.upper())
    if not isinstance(numeric, int):
        fail(f"--log-level: unknown level {level!r}; use debug, info, warning or error")
    logger = logging.getLogger("lookalike.node")
    logger.handlers.clear()
    handler = logging.StreamHandler(sys.stderr)
    handler.setFormatter(logging.Formatter('{"ts":%(created).3f,"level":"%(levelname)s","log":%(message)s}'))
    logger.addHandler(handler)
    logger.setLevel(numeric)
    logger.propagate = False
    return logger


def _address(text: str, option: str) -> tuple[str, int]:
    with failing(ValueError, prefix=f"{option}: "):
        return parse_address(text)


def _destination(text: str, option: str) -> tuple[str, int]:
    """An address to send to, checked (port 1..65535, a host that resolves) before anything starts."""
    with failing(ValueError, prefix=f"{option}: "):
        return resolve_destination(parse_address(text))


_LISTEN = "127.0.0.1:7700"


@app.command()
def serve(
    tracker: str = typer.Option("set", "--tracker", "-t", help="Registered tracker/identifier name (set: any team "
                                "size; lstm: 2, 3 or 7 robots, or --set weights=PATH --set n_slots=M)."),
    set_: list[str] | None = typer.Option(None, "--set", "-s", help="Tracker parameter KEY=VALUE (repeatable)."),
    robots: int = typer.Option(3, help="Robots in the team (ids 0..N-1); also the tracker's n_agents unless set."),
    listen: str = typer.Option(_LISTEN, help="HOST:PORT to receive reports and detections on (port 0: any)."),
    publish: list[str] | None = typer.Option(None, help="HOST:PORT that receives every team state (repeatable)."),
    reply: bool = typer.Option(True, help="Also send each team state to the address every robot reports from."),
    group: str | None = typer.Option(None, help="IPv4 multicast GROUP:PORT that gets each team state once "
                                     "(one send per frame) instead of one reply per robot; robots join it."),
    max_report_age: float = typer.Option(1.0, help="Drop reports sent this many seconds before the last frame."),
    camera_timeout: float = typer.Option(2.0, help="Wall seconds without an accepted frame before the camera counts "
                                         "as lost."),
    rate: float = typer.Option(2000.0, help="Packets/s one sender may send before being rate-limited."),
    burst: float = typer.Option(500.0, help="Packets one sender may send at once."),
    status_interval: float = typer.Option(5.0, help="Seconds between status log lines (0: none)."),
    duration: float = typer.Option(0.0, help="Stop after this many wall seconds (0: run until SIGINT/SIGTERM)."),
    port_file: Path | None = typer.Option(None, help="Write the bound HOST:PORT to this file once listening."),
    log_level: str = typer.Option("info", help="debug, info, warning or error."),
    transport: str = typer.Option("udp", help="udp (JSON datagrams, no extra) or dds: ROS 2 topics over DDS "
                                  "(sensor_msgs/Imu in, geometry_msgs/PoseArray out; the 'ros' extra)."),
    domain_id: int = typer.Option(0, help="With --transport dds: the DDS domain (ROS_DOMAIN_ID)."),
) -> None:
    """Run the observer node: receive heading reports and detections over UDP (or DDS), identify the
    robots with a tracker, publish their positions at the camera rate. Logs are JSON Lines on
    stderr; send a status_request message for the counters."""
    udp_only = [name for name, value in (("--listen", listen != _LISTEN), ("--publish", publish), ("--group", group),
                                         ("--no-reply", not reply), ("--port-file", port_file)) if value]
    if transport == "dds" and udp_only:
        fail(f"{', '.join(udp_only)}: with --transport udp only (over DDS the node has no addresses: it uses ROS 2 "
             "topics in --domain-id)")
    if not duration >= 0:
        fail(f"--duration: wall seconds >= 0 (0: until SIGINT/SIGTERM), got {duration}")
    if not 1 <= robots <= MAX_ROBOTS:  # (before the tracker, which would name its n_agents instead)
        fail(f"--robots: robots in the team, 1 .. {MAX_ROBOTS}, got {robots}")
    listen_address = _address(listen, "--listen")
    check_outputs_or_fail({"--port-file": port_file})
    group_address = _group(group)
    publish_addresses = tuple(_destination(p, "--publish") for p in publish or [])
    settings = list(set_ or [])
    try:
        params = {p.name for p in tracker_parameters(tracker)}
    except KeyError as exc:
        fail(str(exc.args[0]))
    given = {s.split("=", 1)[0].strip(): s.split("=", 1)[-1].strip() for s in settings}
    if "n_agents" in params and "n_agents" not in given:
        settings.append(f"n_agents={robots}")
    elif given.get("n_agents", "").isdigit() and int(given["n_agents"]) < robots:
        fail(f"--set n_agents={given['n_agents']}: fewer than --robots {robots}; every frame with a report of robot "
             f"id {given['n_agents']} or more would fail (leave n_agents out: it follows --robots)")
    slots = {n: m for m, n, _ in map(team_size, PRESET_NAMES)}  # the shipped LSTMs' M per team size N
    if tracker == "lstm" and "n_slots" not in given and robots in slots:
        settings.append(f"n_slots={slots[robots]}")
    trk = build_tracker(tracker, settings)
    log = _logger(log_level)
    try:
        config = NodeConfig(listen=listen_address, publish=publish_addresses,
                            reply_to_robots=reply, group=group_address, sender_rate=rate, sender_burst=burst,
                            camera_timeout_s=camera_timeout, status_interval_s=status_interval)
        id_config = IdentifierConfig(n_robots=robots, max_report_age_s=max_report_age)
        if transport not in ("udp", "dds"):
            raise ValueError(f"--transport: expected udp or dds, got {transport!r}")
        server = NodeServer(trk, config, id_config, log) if transport == "udp" else dds_node(
            trk, domain_id, config, id_config, log)
    except OSError as exc:
        fail(f"--listen {listen}: {exc}")
    except ValueError as exc:
        fail(str(exc))
    with server, SignalStop(duration) as stop:
        if port_file is not None and isinstance(server, NodeServer):
            host, port = server.address
            write_atomic(port_file, f"{host}:{port}\n")
        server.serve(stop)
        if stop.signal is not None:
            log_event(log, "signal", signal=stop.signal)


def _group(text: str | None) -> tuple[str, int] | None:
    if text is None:
        return None
    group = _address(text, "--group")
    with failing(ValueError, prefix="--group: "):
        check_group(group)
    return group


def _clock(start_at: str, speed: float) -> SimClock:
    """``now``, a UNIX time, or ``stdin`` (print ``ready``, then read the UNIX time from stdin)."""
    if start_at == "stdin":
        print("ready", flush=True)
        start_at = sys.stdin.readline().strip()
    with failing(ValueError, prefix="--start-at / --speed: "):
        return SimClock(epoch=time.time() if start_at == "now" else float(start_at), speed=speed)


def _warn(line: str | None) -> None:
    if line is not None:
        print(line, file=sys.stderr, flush=True)


_PRESET_HELP = f"The simulated team: {TEAM_HELP}."
_START_HELP = "Wall time of simulated t=0: now, a UNIX time, or stdin (print 'ready', read it from stdin)."


def _sequence(preset_name: str, seed: int, duration: float, loss: float | None, delay: float | None,
              jitter: float | None) -> Any:
    check_teams("--preset", [preset_name])
    with failing(ValueError, prefix="--duration / --loss / --delay / --jitter: "):
        try:
            return team_sequence(preset_name, seed, duration, loss, delay, jitter)
        except MemoryError:
            fail(f"--duration {duration:g}: the simulated sequence does not fit in memory; give fewer seconds")


@app.command("robot-sim")
def robot_sim(
    robot: int = typer.Option(..., help="This robot's number, 1..N as in the pictures and the labelling page "
                              "(its messages carry the 0-based id robot - 1)."),
    node: str = typer.Option("127.0.0.1:7700", help="The node's HOST:PORT."),
    preset_name: str = typer.Option("m5n3", "--preset", help=_PRESET_HELP),
    seed: int = typer.Option(0, min=0, help="Seed of the shared simulated sequence."),
    duration: float = typer.Option(20.0, help="Simulated seconds."),
    loss: float | None = typer.Option(None, help="Report loss probability (default: the preset's)."),
    delay: float | None = typer.Option(None, help="Report delay, seconds (default: the preset's)."),
    jitter: float | None = typer.Option(None, help="Mean exponential jitter, seconds (default: the preset's)."),
    speed: float = typer.Option(1.0, help="Simulated seconds per wall second (same for the whole team)."),
    start_at: str = typer.Option("now", help=_START_HELP),
    bind: str = typer.Option("127.0.0.1:0", help="Local HOST:PORT to send from and receive positions on."),
    group: str | None = typer.Option(None, help="Also receive team states sent to this multicast GROUP:PORT "
                                     "(the node's --group)."),
    verbose: bool = typer.Option(False, help="Print every received position and its error as JSON on stderr."),
) -> None:
    """A simulated robot: send heading reports to the node over a lossy, jittery link, receive
    the team state, and print the error of its identified position against its true one (JSON)."""
    node_address, bind_address, group_address = _destination(node, "--node"), _address(bind, "--bind"), _group(group)
    sequence = _sequence(preset_name, seed, duration, loss, delay, jitter)
    if not 1 <= robot <= sequence.config.n_agents:
        fail(f"--robot {robot}: team {preset_name} has robots 1..{sequence.config.n_agents}")
    robot -= 1  # the wire protocol's 0-based id
    with failing(OSError, prefix=f"--bind {bind} / --group {group}: "):
        endpoint = Endpoint(node_address, bind_address, group=group_address)

    def show(team: TeamState, error_m: float) -> None:
        mine = next(r for r in team.robots if r.id == robot)
        print(json.dumps({"frame": team.frame, "time": team.time, "position": mine.position, "heading": mine.heading,
                          "confidence": mine.confidence, "age": mine.age, "error_m": round(error_m, 4)}),
              file=sys.stderr, flush=True)

    with endpoint:
        clock = _clock(start_at, speed)
        start_s, late = clock.late_start(f"robot {robot + 1}")
        _warn(late)
        with SignalStop() as stop:
            log = run_robot(endpoint, robot, sequence, clock, stop=stop, on_position=show if verbose else None,
                            start_s=start_s)
    print(json.dumps(log.summary()), flush=True)
    _warn(log.warning())


@app.command("camera-sim")
def camera_sim(
    node: str = typer.Option("127.0.0.1:7700", help="The node's HOST:PORT."),
    preset_name: str = typer.Option("m5n3", "--preset", help=_PRESET_HELP),
    seed: int = typer.Option(0, min=0, help="Seed of the shared simulated sequence."),
    duration: float = typer.Option(20.0, help="Simulated seconds."),
    loss: float | None = typer.Option(None, help="Report loss probability of the team (keeps the sequence shared)."),
    delay: float | None = typer.Option(None, help="Report delay of the team, seconds."),
    jitter: float | None = typer.Option(None, help="Mean jitter of the team, seconds."),
    speed: float = typer.Option(1.0, help="Simulated seconds per wall second (same for the whole team)."),
    start_at: str = typer.Option("now", help=_START_HELP),
    first_frame: int = typer.Option(0, help="Start at this frame (to resume after a crash)."),
) -> None:
    """A simulated camera: send each frame's detections to the node at the camera rate."""
    node_address = _destination(node, "--node")
    sequence = _sequence(preset_name, seed, duration, loss, delay, jitter)
    messages = camera_messages(sequence)[max(first_frame, 0):]
    with Endpoint(node_address) as endpoint:
        clock = _clock(start_at, speed)
        start_s, late = clock.late_start("the camera") if first_frame <= 0 else (-math.inf, None)
        _warn(late)
        failed: list[OSError] = []
        with SignalStop() as stop:
            sent = run_camera(endpoint, messages, clock, stop, start_s, on_send_error=failed.append)
    print(json.dumps({"camera_frames_sent": sent}), flush=True)
    if failed:
        _warn(f"warning: the camera could not send {len(failed)} frames (first: {failed[0]})")
