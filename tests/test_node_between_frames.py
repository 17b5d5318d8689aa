"""Issue 18, fourth pass: work taken off the frame's path gives the same messages, frames and counters.

- ``decode``'s common detections path gives the message the field-by-field checks give (others fall back
  to them and their errors);
- the frame's report columns, made as reports arrive, equal the reports left in the queues (also after a
  full queue dropped one);
- the server prepares the next frame after the send and reports that CPU time beside the frame's.
"""

from __future__ import annotations

import json
import math
import socket

import numpy as np
import pytest

from lookalike.node import IdentifierConfig, TeamIdentifier, decode, encode
from lookalike.node import messages as m
from lookalike.node.counters import NodeCounters
from lookalike.node.messages import DetectionsMessage, HeadingReport, MessageError, numbers_of
from lookalike.node.server import NodeConfig, NodeServer
from lookalike.trackers import make_tracker
from lookalike.types import Frame, TrackSnapshot


def _body(**changes: object) -> dict:
    body = {"v": 1, "type": "detections", "frame": 7, "time": 0.25, "position": [[1.5, -2.0], [0.25, 3.0]],
            "heading": [0.1, -3.0], "score": [0.9, 0.5], "heading_std": [0.05, 0.0]}
    body.update(changes)
    return {k: v for k, v in body.items() if v is not _DROP}


_DROP = object()

AWKWARD = [
    {}, {"heading_std": _DROP}, {"position": [], "heading": [], "score": [], "heading_std": []},
    {"time": 1}, {"frame": True}, {"frame": -1}, {"heading": [1, 0.5]}, {"score": [True, 0.5]},
    {"position": [[1, 2], [0.25, 3.0]]}, {"position": [[1e13, 0.0], [0.25, 3.0]]}, {"heading_std": [-0.1, 0.0]},
    {"heading": [0.1]}, {"position": [[1.0], [2.0, 3.0]]}, {"position": [(1.0, 2.0), [0.25, 3.0]]},
    {"extra": 1}, {"score": _DROP}, {"heading_std": None}, {"time": 1e300}, {"time": "0.1"},
    {"position": [[1.0, 2.0, 3.0], [0.25, 3.0]]}, {"heading": [float("inf"), 0.0]},
]


@pytest.mark.parametrize("changes", AWKWARD)
def test_common_detections_path_equals_the_field_checks(changes: dict) -> None:
    body = _body(**changes)
    fast = m._plain_detections(dict(body))
    try:
        plain: object = m._PARSERS["detections"](_FieldsWithoutFastPath("detections", dict(body)))
    except MessageError as exc:
        plain = exc.reason
    if fast is None:  # (decode then gives the field-by-field result or error)
        try:
            got: object = m._detections(m._Fields("detections", dict(body)))
        except MessageError as exc:
            got = exc.reason
        assert got == plain
        return
    assert fast == plain and type(fast) is DetectionsMessage
    flat = numbers_of(fast)
    assert flat is not None and flat[-1] == fast.time
    n = len(fast.position)
    assert flat[:2 * n] == [v for p in fast.position for v in p]
    assert flat[2 * n:4 * n] == [*fast.heading, *fast.score]
    assert flat[4 * n:-1] == list(fast.heading_std or ())


class _FieldsWithoutFastPath(m._Fields):
    """The message's fields as the checks see them, with the common path switched off."""

    def __init__(self, kind: str, body: dict) -> None:
        super().__init__(kind, body)
        self.body = _NoFast(body)


class _NoFast(dict):
    def keys(self):  # type: ignore[no-untyped-def, override]
        return set(super().keys()) | {"(not the common path)"}


def test_decoded_detections_round_trip_and_numbers_only_from_decode() -> None:
    msg = DetectionsMessage(frame=3, time=0.1, position=((1.0, 2.0), (3.0, 4.5)), heading=(0.1, 0.2),
                            score=(0.9, 0.8), heading_std=(0.05, 0.05))
    decoded = decode(encode(msg))
    assert decoded == msg and encode(decoded) == encode(msg) and repr(decoded) == repr(msg)
    assert numbers_of(msg) is None and numbers_of(decoded) == [1.0, 2.0, 3.0, 4.5, 0.1, 0.2, 0.9, 0.8, 0.05, 0.05, 0.1]
    with pytest.raises(MessageError) as exc:
        decode(json.dumps(_body(heading=[1.0])).encode())
    assert exc.value.reason == "invalid" and "heading" in str(exc.value)


class _Recorder:
    """A tracker that keeps every frame it is given."""

    def __init__(self) -> None:
        self.frames: list[Frame] = []

    def update(self, frame: Frame) -> list[TrackSnapshot]:
        self.frames.append(frame)
        return []

    def reset(self) -> None:
        self.frames.clear()


def _frame_message(k: int) -> DetectionsMessage:
    return DetectionsMessage(frame=k, time=0.1 * k, position=(), heading=(), score=())


def test_report_columns_equal_the_queues_also_after_drops() -> None:
    tracker = _Recorder()
    ident = TeamIdentifier(tracker, IdentifierConfig(n_robots=3, max_queued_per_robot=4))
    rng = np.random.default_rng(0)
    seq = [0, 0, 0]
    for k in range(1, 7):
        expected = []
        for _ in range(int(rng.integers(0, 20))):
            j = int(rng.integers(0, 3))
            seq[j] += 1
            report = HeadingReport(robot=j, seq=seq[j], t_sent=0.1 * (k - 1) + 1e-4 * seq[j],
                                   heading=float(rng.uniform(-3, 3)))
            if ident.add_report(decode(encode(report))) == "reports":
                expected.append(report)
        queued = [r for _, r in sorted(item for q in ident._pending for item in q)]  # (what the frame takes)
        assert len(queued) <= len(expected)
        ident.add_frame(decode(encode(_frame_message(k))))
        b = tracker.frames[-1].beacons
        assert b.agent_id.tolist() == [r.robot for r in queued]
        assert b.t_sent.tolist() == [r.t_sent for r in queued] and b.heading.tolist() == [r.heading for r in queued]
        assert np.all(b.t_received == 0.1 * k)
    assert ident.queue_dropped > 0


def test_reports_that_are_not_finite_still_meet_the_checks() -> None:
    ident = TeamIdentifier(_Recorder(), IdentifierConfig(n_robots=2))
    with pytest.raises(ValueError, match="heading"):  # (checked as it arrives, before it reaches a frame)
        ident.add_report(HeadingReport(robot=0, seq=1, t_sent=0.0, heading=math.nan))
    assert ident.queued == 0 and ident.add_frame(_frame_message(1))[0] == "frames"


def test_counters_report_cpu_time_with_the_prepared_next_frame() -> None:
    counters = NodeCounters()
    counters.cpu_s.extend([0.001, 0.003])
    counters.cpu_with_prepare_s.extend([0.0015, 0.0035])
    snap = counters.snapshot()
    assert snap["cpu_with_prepare_ms"]["median"] == pytest.approx(2.5)


def test_server_prepares_the_next_frame_after_the_send() -> None:
    with NodeServer(make_tracker("kalman_ha2", n_agents=2), NodeConfig(publish=(("127.0.0.1", 9),)),
                    IdentifierConfig(n_robots=2)) as node:
        with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as camera:
            for k in range(3):
                message = DetectionsMessage(frame=k, time=k / 30, position=((1.0, 0.5),), heading=(0.1,),
                                            score=(0.9,))
                camera.sendto(encode(message), node.address)
                node.poll(1.0)
        snap = node.counters.snapshot()
        assert snap["frames"] == 3 and snap["tracker_errors"] == 0
        assert snap["cpu_with_prepare_ms"]["frames"] == 3
        assert snap["cpu_with_prepare_ms"]["median"] >= snap["cpu_ms"]["median"] - 1e-3
        assert node.identifier.tracker._ready  # (the next frame's prediction is ready)
