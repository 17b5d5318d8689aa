"""The node's wire format: round trips and every rejection reason."""

import json
import math

import pytest

from lookalike.node import (
    SCHEMA_VERSION,
    DetectionsMessage,
    HeadingReport,
    MessageError,
    RobotEstimate,
    Status,
    StatusRequest,
    TeamState,
    decode,
    encode,
)
from lookalike.node import messages as m


def _raw(**body):
    return json.dumps({"v": SCHEMA_VERSION, **body}).encode()


@pytest.mark.parametrize(
    "message",
    [
        HeadingReport(robot=2, seq=7, t_sent=1.25, heading=-3.0),
        DetectionsMessage(frame=4, time=0.4, position=((1.0, 2.0), (-0.5, 3.25)), heading=(0.1, 2.0), score=(1.0, 0.5)),
        DetectionsMessage(frame=0, time=0.0, position=(), heading=(), score=()),
        DetectionsMessage(frame=1, time=0.1, position=((1.0, 2.0),), heading=(0.1,), score=(1.0,), heading_std=(0.3,)),
        TeamState(frame=3, time=0.3, robots=(RobotEstimate(0, (1.0, 2.0), 0.5, 0.9, 0.0),
                                             RobotEstimate(1, (0.0, -1.0), None, None, 0.7)), labels=(0, -1, 1)),
        StatusRequest(),
        Status(counters={"received": 3, "rejected": {"malformed": 1}}),
    ],
)
def test_round_trip(message):
    assert decode(encode(message)) == message


@pytest.mark.parametrize(
    "data", [b"{", b"\xff\xfe", b"", b"[1, 2]", b"null", b'{"v": 1, "type": "report", "robot": NaN}']
)
def test_malformed(data):
    with pytest.raises(MessageError) as err:
        decode(data)
    assert err.value.reason == m.MALFORMED


@pytest.mark.parametrize("version", [0, 2, "1", True, None])
def test_wrong_version(version):
    body = {"type": "status_request"} if version is None else {"v": version, "type": "status_request"}
    with pytest.raises(MessageError) as err:
        decode(json.dumps(body).encode())
    assert err.value.reason == m.VERSION
    assert "version" in str(err.value)


def test_unknown_type_and_too_large():
    with pytest.raises(MessageError) as err:
        decode(_raw(type="launch"))
    assert err.value.reason == m.UNKNOWN_TYPE and "launch" in err.value.detail
    with pytest.raises(MessageError) as err:
        decode(b" " * (m.MAX_DATAGRAM_BYTES + 1))
    assert err.value.reason == m.TOO_LARGE


@pytest.mark.parametrize(
    "body, field",
    [
        ({"type": "report", "seq": 1, "t_sent": 0.0, "heading": 0.0}, "robot"),
        ({"type": "report", "robot": True, "seq": 1, "t_sent": 0.0, "heading": 0.0}, "robot"),
        ({"type": "report", "robot": -1, "seq": 1, "t_sent": 0.0, "heading": 0.0}, "robot"),
        ({"type": "report", "robot": 0, "seq": 1.5, "t_sent": 0.0, "heading": 0.0}, "seq"),
        ({"type": "report", "robot": 0, "seq": 1, "t_sent": "now", "heading": 0.0}, "t_sent"),
        ({"type": "report", "robot": 0, "seq": 1, "t_sent": 0.0, "heading": "__INF__"}, "heading"),
        ({"type": "report", "robot": 0, "seq": 1, "t_sent": 0.0, "heading": 0.0, "extra": 1}, "extra"),
        ({"type": "detections", "frame": 0, "time": 0.0, "position": [[0, 0]], "heading": [], "score": [1]}, "heading"),
        ({"type": "detections", "frame": 0, "time": 0.0, "position": [[0, 0, 0]], "heading": [0], "score": [1]},
         "position[0]"),
        ({"type": "detections", "frame": 0, "time": 0.0, "position": {"x": 1}, "heading": [], "score": []}, "position"),
        ({"type": "detections", "frame": 0, "time": 0.0, "position": [[0, 0]], "heading": [0], "score": [1],
          "heading_std": [0.1, 0.2]}, "heading_std"),
        ({"type": "detections", "frame": 0, "time": 0.0, "position": [[0, 0]] * 300, "heading": [0] * 300,
          "score": [1] * 300}, "position"),
        ({"type": "team", "frame": 0, "time": 0.0, "robots": [{"id": 0}], "labels": []}, "position"),
        ({"type": "team", "frame": 0, "time": 0.0, "robots": [], "labels": [-2]}, "labels"),
        ({"type": "status", "counters": [1]}, "counters"),
    ],
)
def test_invalid_fields_are_named(body, field):
    with pytest.raises(MessageError) as err:
        decode(_raw(**body).replace(b'"__INF__"', b"1e999"))  # JSON text whose number overflows
    assert err.value.reason == m.INVALID
    assert field in err.value.detail


def test_encode_refuses_non_finite_numbers():
    with pytest.raises(ValueError, match="non-finite"):
        encode(HeadingReport(robot=0, seq=0, t_sent=math.nan, heading=0.0))
    with pytest.raises(ValueError, match="cannot encode"):
        encode("hello")  # type: ignore[arg-type]
