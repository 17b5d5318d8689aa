"""Simulated robot and camera processes that talk to the node, from a shared :func:`team_sequence`."""

from __future__ import annotations

import dataclasses
import math
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from lookalike.node.client import Endpoint
from lookalike.node.messages import DetectionsMessage, HeadingReport, TeamState
from lookalike.sim.presets import preset
from lookalike.sim.robots import RobotSequence, simulate_robots


@dataclass(frozen=True)
class SimClock:
    """Simulated time ``t`` happens at wall time ``epoch + t / speed`` (``time.time()`` seconds)."""

    epoch: float
    speed: float = 1.0

    def __post_init__(self) -> None:
        if not (self.speed > 0 and math.isfinite(self.speed)):
            raise ValueError(f"SimClock.speed must be a positive number, got {self.speed!r}")

    def now(self) -> float:
        """The simulated time now, seconds."""
        return (time.time() - self.epoch) * self.speed

    def late_start(self, who: str, tolerance_s: float = 0.5) -> tuple[float, str | None]:
        """Where a process started now begins, simulated seconds, and a warning line: ``(0, None)`` on time, else,
        when t=0 passed more than ``tolerance_s`` wall seconds ago, the present and a line saying that ``who``
        (e.g. ``"robot 2"``) skips what was due before (sent at once, it would reach the node too late)."""
        late_s = time.time() - self.epoch
        if late_s <= tolerance_s:
            return 0.0, None
        start = self.now()
        return start, (f"warning: {who} started {late_s:.1f} s after --start-at; skipping the first {start:.1f} "
                       f"simulated s (give every process a later --start-at)")

    def wait_until(self, t_sim: float, stop: Callable[[], bool] = lambda: False) -> bool:
        """Sleep until simulated time ``t_sim``; False when ``stop()`` became true first."""
        while not stop():
            remaining = self.epoch + t_sim / self.speed - time.time()
            if remaining <= 0:
                return True
            time.sleep(min(remaining, 0.05))
        return False


def team_sequence(preset_name: str, seed: int, duration_s: float, loss: float | None = None,
                  delay_s: float | None = None, jitter_s: float | None = None) -> RobotSequence:
    """``duration_s`` seconds of a preset, with the network's loss, delay and jitter (s) replaced where given."""
    if not duration_s > 0:
        raise ValueError(f"duration_s must be > 0, got {duration_s!r}")
    config = preset(preset_name)
    changes = {k: v for k, v in (("loss_prob", loss), ("delay_s", delay_s), ("jitter_s", jitter_s)) if v is not None}
    config = dataclasses.replace(config, network=dataclasses.replace(config.network, **changes))
    n_frames = round(duration_s * config.frame_rate_hz) + 1
    return simulate_robots(config, n_frames, seed)


def camera_messages(sequence: RobotSequence) -> list[DetectionsMessage]:
    """One detections message per frame (positions, headings, scores; never the labels)."""
    a = sequence.arrays
    std = float(sequence.config.sensor.heading_std_rad)
    return [DetectionsMessage(
        frame=k, time=float(a.time[k]), position=tuple((float(x), float(y)) for x, y in a.det_position[k, :n]),
        heading=tuple(float(h) for h in a.det_heading[k, :n]), score=tuple(float(s) for s in a.det_score[k, :n]),
        heading_std=(std,) * n,
    ) for k, n in enumerate(a.det_valid.sum(axis=1).tolist())]


def robot_reports(sequence: RobotSequence, robot: int) -> list[tuple[float, HeadingReport]]:
    """Robot ``robot``'s delivered reports as ``(t_received, report)`` in delivery order; ``seq`` follows send order."""
    if not 0 <= robot < sequence.config.n_agents:
        raise ValueError(f"robot {robot} is not in a team of {sequence.config.n_agents}")
    r = sequence.arrays.reports
    mine = np.flatnonzero(r.agent_id == robot)
    period = 1.0 / sequence.config.network.rate_hz
    first = float(r.t_sent[mine].min()) if mine.size else 0.0
    reports = [(float(r.t_received[i]), HeadingReport(robot=robot, seq=round(float(r.t_sent[i] - first) / period),
                                                      t_sent=float(r.t_sent[i]), heading=float(r.heading[i])))
               for i in mine]
    return sorted(reports, key=lambda item: item[0])


def run_camera(endpoint: Endpoint, messages: Sequence[DetectionsMessage], clock: SimClock,
               stop: Callable[[], bool] = lambda: False, start_s: float = -math.inf,
               on_send_error: Callable[[OSError], None] | None = None) -> int:
    """Send each frame at its simulated time, from simulated time ``start_s`` on; return how many were sent. A frame
    the OS refuses to send (e.g. the network is down) is lost, as on a lossy link, and given to ``on_send_error``."""
    sent = 0
    for message in messages:
        if message.time < start_s:
            continue
        if not clock.wait_until(message.time, stop):
            break
        try:
            endpoint.send(message)
        except OSError as exc:
            if on_send_error is not None:
                on_send_error(exc)
            continue
        sent += 1
    return sent


@dataclass
class RobotLog:
    """What a simulated robot saw: reports sent, reports the OS refused to send (the first error's text), team states
    received, its position errors (metres)."""

    robot: int
    reports_sent: int = 0
    team_states: int = 0
    errors_m: list[float] = dataclasses.field(default_factory=list)
    send_errors: int = 0
    first_send_error: str | None = None

    def warning(self) -> str | None:
        """A warning line when no team state gave this robot's position (its errors are then ``null``), or when
        reports could not be sent."""
        lines = []
        if self.send_errors:
            lines.append(f"warning: robot {self.robot + 1} could not send {self.send_errors} reports (first: "
                         f"{self.first_send_error})")
        if not self.errors_m:
            heard = "no team state" if self.team_states == 0 else f"{self.team_states} team states but none with it"
            lines.append(f"warning: robot {self.robot + 1} received {heard}: is the node running, and did the camera "
                         f"start at the same --start-at?")
        return "\n".join(lines) or None

    def summary(self) -> dict[str, float | int | None]:
        """JSON-ready figures: counts, median and 95th-percentile position error in metres."""
        err = np.asarray(self.errors_m)
        return {
            "robot": self.robot, "reports_sent": self.reports_sent, "send_errors": self.send_errors,
            "team_states": self.team_states,
            "positions": int(err.size),
            "median_error_m": round(float(np.median(err)), 4) if err.size else None,
            "p95_error_m": round(float(np.percentile(err, 95)), 4) if err.size else None,
        }


def run_robot(endpoint: Endpoint, robot: int, sequence: RobotSequence, clock: SimClock,
              linger_s: float = 0.5, stop: Callable[[], bool] = lambda: False,
              on_position: Callable[[TeamState, float], None] | None = None,
              start_s: float = -math.inf) -> RobotLog:
    """Send robot ``robot``'s reports on time (those due from simulated time ``start_s`` on), receive team states and
    log the error (m) of the node's estimate of this robot (also to ``on_position(team_state, error_m)``); stop
    ``linger_s`` after the last frame."""
    log = RobotLog(robot)
    truth = sequence.arrays.true_position[:, robot]
    schedule = [item for item in robot_reports(sequence, robot) if item[0] >= start_s]
    end = float(sequence.arrays.time[-1]) + linger_s
    i = 0
    while not stop():
        t_next = schedule[i][0] if i < len(schedule) else end
        now = clock.now()
        if now >= t_next:
            if i >= len(schedule):
                break
            i += 1
            try:
                endpoint.send(schedule[i - 1][1])
            except OSError as exc:  # (the network is down: lost, as on a lossy link)
                log.send_errors += 1
                log.first_send_error = log.first_send_error or str(exc)
                continue
            log.reports_sent += 1
            continue
        message = endpoint.receive(min((t_next - now) / clock.speed, 0.05))
        if isinstance(message, TeamState):
            log.team_states += 1
            for estimate in message.robots:
                if estimate.id == robot and 0 <= message.frame < len(truth):
                    error = float(np.hypot(*(np.asarray(estimate.position) - truth[message.frame])))
                    log.errors_m.append(error)
                    if on_position is not None:
                        on_position(message, error)
    return log

