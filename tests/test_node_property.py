"""Issue 19: property-based tests of the node's message parsing. Arbitrary bytes and arbitrary
JSON never raise anything but ``MessageError``, never reach the loop as an exception, and valid
messages round-trip."""

from __future__ import annotations

import json
import sys
from pathlib import Path

from hypothesis import given, settings
from hypothesis import strategies as st

from lookalike.node import (
    SCHEMA_VERSION,
    DetectionsMessage,
    HeadingReport,
    MessageError,
    NodeServer,
    decode,
    encode,
)
from lookalike.node import messages as m

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))
from _soak import EXCLUSIVE, LatestHeadingMatcher  # noqa: E402  (the soak benchmark's helpers)

scalars = (st.none() | st.booleans() | st.integers(min_value=-(2**80), max_value=2**80)
           | st.floats(allow_nan=False, allow_infinity=False) | st.text(max_size=10))
json_values = st.recursive(scalars, lambda c: st.lists(c, max_size=4) | st.dictionaries(st.text(max_size=8), c,
                                                                                          max_size=4), max_leaves=12)
FIELDS = ["robot", "seq", "t_sent", "heading", "frame", "time", "position", "score", "heading_std", "robots",
          "labels", "counters", "id", "age", "confidence"]
message_like = st.fixed_dictionaries(
    {"v": st.sampled_from([SCHEMA_VERSION, SCHEMA_VERSION, 0, "1"]),
     "type": st.sampled_from(["report", "detections", "team", "status", "status_request", "x"])},
    optional={name: json_values for name in FIELDS},
)


def _decode_or_reason(data: bytes) -> str:
    try:
        decode(data)
    except MessageError as exc:
        assert exc.reason in (m.MALFORMED, m.TOO_LARGE, m.VERSION, m.UNKNOWN_TYPE, m.INVALID)
        assert len(exc.detail) < 1000
        return exc.reason
    return "ok"


@settings(max_examples=300, deadline=None)
@given(st.binary(max_size=300))
def test_arbitrary_bytes_raise_only_message_error(data):
    _decode_or_reason(data)


@settings(max_examples=150, deadline=None)
@given(message_like)
def test_arbitrary_message_like_json_raises_only_message_error(body):
    data = json.dumps(body).encode()
    if _decode_or_reason(data) == "ok":  # anything accepted encodes again within the bounds
        assert decode(encode(decode(data))) == decode(data)


finite = st.floats(min_value=-1e12, max_value=1e12, allow_nan=False)
int64 = st.integers(min_value=0, max_value=2**63 - 1)


@settings(max_examples=200, deadline=None)
@given(robot=int64, seq=int64, t=finite, h=finite)
def test_valid_reports_round_trip(robot, seq, t, h):
    report = HeadingReport(robot=robot, seq=seq, t_sent=t, heading=h)
    assert decode(encode(report)) == report


@settings(max_examples=100, deadline=None)
@given(frame=int64, time=finite, rows=st.lists(st.tuples(finite, finite, finite, finite), max_size=m.MAX_DETECTIONS))
def test_valid_detections_round_trip(frame, time, rows):
    msg = DetectionsMessage(frame=frame, time=time, position=tuple((x, y) for x, y, _, _ in rows),
                            heading=tuple(h for _, _, h, _ in rows), score=tuple(s for _, _, _, s in rows))
    assert decode(encode(msg)) == msg


@settings(max_examples=60, deadline=None)
@given(st.lists(st.one_of(st.binary(max_size=120), message_like.map(lambda b: json.dumps(b).encode())),
                max_size=12))
def test_the_node_loop_never_raises_and_counts_every_datagram(datagrams):
    node = NodeServer(LatestHeadingMatcher(3))
    try:
        for k, data in enumerate(datagrams):
            node.handle(data, ("127.0.0.1", 40000 + k % 3), float(k))
        c = node.counters.snapshot()
        assert c["received"] == len(datagrams)
        assert c["received"] == sum(c[name] for name in EXCLUSIVE) + c["rejected_total"]
        assert c["handler_errors"] == 0 and c["tracker_errors"] == 0
    finally:
        node.close()
