"""The node's wire format: versioned messages (:mod:`lookalike.node.schema`) as compact UTF-8 JSON, one per UDP
datagram, each with ``"v"`` and ``"type"``; ``decode`` raises only ``MessageError`` (a stable ``reason`` code)."""

from __future__ import annotations

import json
import math
from collections.abc import Callable
from itertools import chain
from math import isfinite
from typing import Any, cast

from lookalike.node.schema import (
    INVALID,
    MALFORMED,
    MAX_ABS_NUMBER,
    MAX_COUNTERS,
    MAX_DATAGRAM_BYTES,
    MAX_DETAIL_CHARS,
    MAX_DETECTIONS,
    MAX_INT,
    MAX_KEY_CHARS,
    MAX_ROBOTS,
    SCHEMA_VERSION,
    TOO_LARGE,
    UNEXPECTED,
    UNKNOWN_TYPE,
    VERSION,
    DetectionsMessage,
    HeadingReport,
    Message,
    MessageError,
    RobotEstimate,
    Status,
    StatusRequest,
    TeamState,
)

# (the messages and bounds are defined in lookalike.node.schema and importable from here too)
__all__ = [
    "check_bounds",
    "DetectionsMessage",
    "HeadingReport",
    "INVALID",
    "MALFORMED",
    "MAX_ABS_NUMBER",
    "MAX_COUNTERS",
    "MAX_DATAGRAM_BYTES",
    "MAX_DETAIL_CHARS",
    "MAX_DETECTIONS",
    "MAX_INT",
    "MAX_KEY_CHARS",
    "MAX_ROBOTS",
    "Message",
    "MessageError",
    "RobotEstimate",
    "SCHEMA_VERSION",
    "Status",
    "StatusRequest",
    "TOO_LARGE",
    "TeamState",
    "UNEXPECTED",
    "UNKNOWN_TYPE",
    "VERSION",
    "decode",
    "encode",
    "numbers_of",
]

_TYPE_OF = {
    HeadingReport: "report",
    DetectionsMessage: "detections",
    TeamState: "team",
    StatusRequest: "status_request",
    Status: "status",
}


def encode(message: Message) -> bytes:
    """The datagram of ``message`` (compact UTF-8 JSON); raises ``ValueError`` for non-finite numbers."""
    kind = _TYPE_OF.get(type(message))
    if kind is None:
        raise ValueError(f"message: cannot encode {type(message).__name__}")
    if kind == "team":
        fast = _team_bytes(message)  # type: ignore[arg-type]
        if fast is not None and len(fast) <= MAX_DATAGRAM_BYTES:
            return fast
    body: dict[str, Any] = {"v": SCHEMA_VERSION, "type": kind}
    if isinstance(message, TeamState):
        body.update(
            frame=message.frame, time=message.time, labels=list(message.labels),
            robots=[
                {"id": r.id, "position": list(r.position), "heading": r.heading,
                 "confidence": r.confidence, "age": r.age}
                for r in message.robots
            ],
        )
    elif isinstance(message, DetectionsMessage):
        body.update(frame=message.frame, time=message.time, position=[list(p) for p in message.position],
                    heading=list(message.heading), score=list(message.score))
        if message.heading_std is not None:
            body["heading_std"] = list(message.heading_std)
    elif isinstance(message, Status):
        body["counters"] = message.counters
    elif isinstance(message, HeadingReport):
        body.update(robot=message.robot, seq=message.seq, t_sent=message.t_sent, heading=message.heading)
    try:
        data = json.dumps(body, separators=(",", ":"), allow_nan=False).encode()
    except ValueError:
        raise ValueError(f"{kind} message: holds a non-finite number") from None
    if len(data) > MAX_DATAGRAM_BYTES:
        raise ValueError(f"{kind} message: {len(data)} bytes exceeds {MAX_DATAGRAM_BYTES}")
    return data


def _team_bytes(message: TeamState) -> bytes | None:
    """A team state's datagram written directly (as ``json.dumps`` would), or None when not plain numbers."""
    robots = []
    for r in message.robots:
        if len(r.position) != 2:
            return None
        x, y = r.position
        h, c, age = r.heading, r.confidence, r.age
        if not (type(r.id) is int and type(x) is float and type(y) is float and type(age) is float
                and (h is None or type(h) is float) and (c is None or type(c) is float)
                and isfinite(x + y + age + (0.0 if h is None else h) + (0.0 if c is None else c))):
            return None
        robots.append(_ROBOT.format(_int_repr(r.id), _float_repr(x), _float_repr(y),
                                    "null" if h is None else _float_repr(h), "null" if c is None else _float_repr(c),
                                    _float_repr(age)))
    frame, time, labels = message.frame, message.time, message.labels
    if not (type(frame) is int and type(time) is float and isfinite(time)
            and all(type(v) is int for v in labels)):
        return None
    return _TEAM.format(SCHEMA_VERSION, _int_repr(frame), _float_repr(time), ",".join(map(_int_repr, labels)),
                        ",".join(robots)).encode()


_float_repr = float.__repr__
_int_repr = int.__repr__
_ROBOT = '{{"id":{},"position":[{},{}],"heading":{},"confidence":{},"age":{}}}'
_TEAM = '{{"v":{},"type":"team","frame":{},"time":{},"labels":[{}],"robots":[{}]}}'


def decode(data: bytes) -> Message:
    """Parse and validate one datagram; raises ``MessageError`` with a reason code."""
    if len(data) > MAX_DATAGRAM_BYTES:
        raise MessageError(TOO_LARGE, f"{len(data)} bytes exceeds {MAX_DATAGRAM_BYTES}")
    try:
        text = data.decode("utf-8")
        if text.startswith("\ufeff"):
            body = json.loads(text, parse_constant=_reject_constant)
        else:
            body = _scan_object(text)
    except (UnicodeDecodeError, ValueError, RecursionError) as exc:
        raise MessageError(MALFORMED, f"not UTF-8 JSON ({exc})") from None
    if not isinstance(body, dict):
        raise MessageError(MALFORMED, f"expected a JSON object, got {type(body).__name__}")
    version = body.get("v")
    if version != SCHEMA_VERSION or isinstance(version, bool):
        raise MessageError(VERSION, f"schema version {version!r}, this node speaks {SCHEMA_VERSION}")
    kind = body.get("type")
    parser = _PARSERS.get(kind) if isinstance(kind, str) else None
    if parser is None or not isinstance(kind, str):
        raise MessageError(UNKNOWN_TYPE, f"type {kind!r}; known: {sorted(_PARSERS)}")
    return parser(_Fields(kind, body))


def _reject_constant(name: str) -> Any:
    raise ValueError(f"{name} is not allowed")


_DECODER = json.JSONDecoder(parse_constant=_reject_constant)
_SCAN = _DECODER.scan_once  # type: ignore[attr-defined]  # (the C scanner decode calls)


def _scan_object(text: str) -> Any:
    """``_DECODER.decode(text)``, scanning a bare JSON object directly."""
    if text.startswith("{"):
        try:
            body, end = _SCAN(text, 0)
        except StopIteration:
            end = -1
        if end == len(text):
            return body
    return _DECODER.decode(text)


class _Fields:
    """Typed access to a message's fields, raising ``MessageError(INVALID)`` naming the field."""

    def __init__(self, kind: str, body: dict[str, Any]) -> None:
        self.kind, self.body = kind, body
        self.used = {"v", "type"}

    def _get(self, name: str, optional: bool = False) -> Any:
        self.used.add(name)
        if name not in self.body:
            if optional:
                return None
            raise self.error(name, "is missing")
        return self.body[name]

    def error(self, name: str, problem: str) -> MessageError:
        return MessageError(INVALID, f"{self.kind}.{name} {problem}")

    def integer(self, name: str, minimum: int = 0) -> int:
        value = self._get(name)
        if isinstance(value, bool) or not isinstance(value, int):
            raise self.error(name, f"must be an integer, got {_quote(value)}")
        if not minimum <= value <= MAX_INT:
            raise self.error(name, f"must be in {minimum} .. {MAX_INT}, got {_quote(value)}")
        return value

    def number(self, name: str, optional: bool = False) -> float | None:
        value = self._get(name, optional)
        if value is None and optional:
            return None
        return self._finite(name, value)

    def _finite(self, name: str, value: Any, minimum: float = -MAX_ABS_NUMBER) -> float:
        # (ints are compared before any float conversion: a 400-digit integer must not overflow)
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not (
                minimum <= value <= MAX_ABS_NUMBER and math.isfinite(value)):
            raise self.error(name, f"must be a finite number in {minimum:g} .. {MAX_ABS_NUMBER:g}, got {_quote(value)}")
        return float(value)

    def numbers(self, name: str, length: int | None = None, optional: bool = False,
                minimum: float = -MAX_ABS_NUMBER) -> tuple[float, ...] | None:
        value = self._get(name, optional)
        if value is None and optional:
            return None
        if not isinstance(value, list):
            raise self.error(name, f"must be a list, got {type(value).__name__}")
        if length is not None and len(value) != length:
            raise self.error(name, f"has {len(value)} entries, expected {length}")
        if len(value) > MAX_DETECTIONS:
            raise self.error(name, f"has {len(value)} entries, at most {MAX_DETECTIONS} allowed")
        fast = _plain_numbers(value, minimum)
        if fast is not None:
            return fast
        return tuple(self._finite(f"{name}[{i}]", v, minimum) for i, v in enumerate(value))

    def finish(self) -> None:
        unknown = sorted(set(self.body) - self.used)
        if unknown:
            raise MessageError(INVALID, f"{self.kind}: unknown field(s) {_quote(unknown)}")


def _plain_numbers(values: list[Any], minimum: float) -> tuple[float, ...] | None:
    """``values`` as floats when every one is a JSON float (or a small int) within the bounds, else None."""
    kinds = set(map(type, values))
    if kinds <= _FLOAT:
        out = tuple(values)
    elif kinds <= _FLOAT_INT and all(-(2**53) <= v <= 2**53 for v in values if type(v) is int):
        out = tuple(float(v) for v in values)
    else:
        return None
    if out and not (minimum <= min(out) and max(out) <= MAX_ABS_NUMBER):  # (NaN cannot come from JSON here)
        return None
    return out


_FLOAT = {float}
_FLOAT_INT = {float, int}
_LIST = {list}
_PAIR = {2}


def _quote(value: Any) -> str:
    """``repr(value)`` cut to ``MAX_DETAIL_CHARS`` characters (details are logged; peers choose values)."""
    if isinstance(value, int) and not isinstance(value, bool) and abs(value) > 10**30:
        return f"an integer of {len(str(abs(value)))} digits"
    text = repr(value)
    return text if len(text) <= MAX_DETAIL_CHARS else text[:MAX_DETAIL_CHARS] + "..."


def _report(f: _Fields) -> HeadingReport:
    msg = HeadingReport(robot=f.integer("robot"), seq=f.integer("seq"), t_sent=f.number("t_sent"),  # type: ignore[arg-type]
                        heading=f.number("heading"))  # type: ignore[arg-type]
    f.finish()
    return msg


_DETECTION_FIELDS = frozenset({"v", "type", "frame", "time", "position", "heading", "score", "heading_std"})


def numbers_of(message: DetectionsMessage) -> list[float] | None:
    """A ``decode``d detections message's numbers as one flat list (positions, headings, scores, spreads, time)."""
    flat: list[float] | None = message.__dict__.get("_numbers")
    return flat


def _plain_detections(body: dict[str, Any]) -> DetectionsMessage | None:
    """The common detections message in few steps; None for anything else (checked field by field)."""
    if not body.keys() <= _DETECTION_FIELDS:
        return None
    frame, raw, heading, score = body.get("frame"), body.get("position"), body.get("heading"), body.get("score")
    spread = body.get("heading_std")
    if not (type(frame) is int and 0 <= frame <= MAX_INT and type(raw) is list and type(heading) is list
            and type(score) is list and (spread is None or type(spread) is list)):
        return None
    n = len(raw)
    if (n > MAX_DETECTIONS or len(heading) != n or len(score) != n or (spread is not None and len(spread) != n)
            or not (set(map(type, raw)) <= _LIST and set(map(len, raw)) <= _PAIR)):
        return None
    flat = list(chain.from_iterable(raw))
    flat += heading
    flat += score
    if spread is not None:
        flat += spread
    flat.append(body.get("time"))
    if not (set(map(type, flat)) <= _FLOAT and -MAX_ABS_NUMBER <= min(flat) and max(flat) <= MAX_ABS_NUMBER
            and (not spread or min(spread) >= 0.0)):
        return None
    msg = object.__new__(DetectionsMessage)  # (the fields set directly: checked above)
    msg.__dict__.update(frame=frame, time=flat[-1], position=tuple(zip(flat[0:2 * n:2], flat[1:2 * n:2])),
                        heading=tuple(heading),
                        score=tuple(score), heading_std=None if spread is None else tuple(spread), _numbers=flat)
    return msg


def _detections(f: _Fields) -> DetectionsMessage:
    fast = _plain_detections(f.body)
    if fast is not None:
        return fast
    frame, time = f.integer("frame"), f.number("time")
    raw = f._get("position")
    if not isinstance(raw, list) or len(raw) > MAX_DETECTIONS:
        raise f.error("position", f"must be a list of at most {MAX_DETECTIONS} [x, y] pairs")
    if not (set(map(type, raw)) <= _LIST and set(map(len, raw)) <= _PAIR):
        for i, pair in enumerate(raw):
            if not isinstance(pair, list) or len(pair) != 2:
                raise f.error(f"position[{i}]", f"must be an [x, y] pair, got {_quote(pair)}")
    flat = _plain_numbers(list(chain.from_iterable(raw)), -MAX_ABS_NUMBER)
    if flat is not None:
        position = tuple(zip(flat[0::2], flat[1::2]))
    else:
        position = tuple((f._finite(f"position[{i}]", pair[0]), f._finite(f"position[{i}]", pair[1]))
                         for i, pair in enumerate(raw))
    msg = DetectionsMessage(frame=frame, time=time, position=position,  # type: ignore[arg-type]
                            heading=f.numbers("heading", len(raw)), score=f.numbers("score", len(raw)),  # type: ignore[arg-type]
                            heading_std=f.numbers("heading_std", len(raw), optional=True, minimum=0.0))
    f.finish()
    return msg


def _team(f: _Fields) -> TeamState:
    frame, time = f.integer("frame"), f.number("time")
    raw = f._get("robots")
    if not isinstance(raw, list) or len(raw) > MAX_ROBOTS:
        raise f.error("robots", f"must be a list of at most {MAX_ROBOTS} robot estimates")
    robots = []
    for i, item in enumerate(raw):
        if not isinstance(item, dict):
            raise f.error(f"robots[{i}]", "must be an object")
        sub = _Fields(f"team.robots[{i}]", item)
        sub.used.clear()
        pos = cast(tuple[float, float], sub.numbers("position", 2))
        robots.append(RobotEstimate(id=sub.integer("id"), position=(pos[0], pos[1]),
                                    heading=sub.number("heading", True),
                                    confidence=sub.number("confidence", True), age=sub.number("age")))  # type: ignore[arg-type]
        sub.finish()
    labels = f._get("labels")
    if not isinstance(labels, list) or len(labels) > MAX_DETECTIONS or any(
            isinstance(v, bool) or not isinstance(v, int) or not -1 <= v <= MAX_INT for v in labels):
        raise f.error("labels", f"must be a list of at most {MAX_DETECTIONS} integers in -1 .. {MAX_INT}")
    msg = TeamState(frame=frame, time=time, robots=tuple(robots), labels=tuple(labels))  # type: ignore[arg-type]
    f.finish()
    return msg


def _status_request(f: _Fields) -> StatusRequest:
    f.finish()
    return StatusRequest()


def _status(f: _Fields) -> Status:
    counters = f._get("counters")
    if not isinstance(counters, dict) or _count_entries(counters) > MAX_COUNTERS:
        raise f.error("counters", f"must be an object of at most {MAX_COUNTERS} entries")
    _check_counters(f, counters, "counters")
    f.finish()
    return Status(counters=counters)


def _count_entries(obj: dict[str, Any], depth: int = 0) -> int:
    """Entries of ``obj`` and its nested objects (more than ``MAX_COUNTERS`` when nested too deep)."""
    if depth > 3:
        return MAX_COUNTERS + 1
    return len(obj) + sum(_count_entries(v, depth + 1) for v in obj.values() if isinstance(v, dict))


def _check_counters(f: _Fields, obj: dict[str, Any], where: str) -> None:
    """Counter names are short strings; values numbers (bounded), null or nested counter objects."""
    for key, value in obj.items():
        if len(key) > MAX_KEY_CHARS:
            raise f.error(where, f"has a key of {len(key)} characters, at most {MAX_KEY_CHARS} allowed")
        if isinstance(value, dict):
            _check_counters(f, value, f"{where}.{key}")
        elif value is not None:
            f._finite(f"{where}.{key}", value)



def check_bounds(message: HeadingReport | DetectionsMessage) -> None:
    """Raise ``MessageError(INVALID)`` naming the field unless ``message`` (made in Python, or converted from ROS 2)
    holds what :func:`decode` lets through: its fields are checked by the wire's own parser (numpy numbers taken as
    the Python numbers they hold)."""
    kind = "report" if isinstance(message, HeadingReport) else "detections"
    body = {name: _as_json(value) for name, value in vars(message).items()
            if not name.startswith("_") and value is not None}
    for name, value in body.items():  # (JSON has no NaN or infinity, so the parser's fast paths do not look for them)
        if not _all_finite(value):
            raise MessageError(INVALID, f"{kind}.{name} must hold finite numbers, got {_quote(value)}")
    _PARSERS[kind](_Fields(kind, body))


def _all_finite(value: Any) -> bool:
    if isinstance(value, list):
        return all(map(_all_finite, value))
    return not isinstance(value, float) or math.isfinite(value)


def _as_json(value: Any) -> Any:
    """A field made in Python as JSON carries it: sequences as lists, numpy numbers as Python numbers."""
    if isinstance(value, (tuple, list)):
        return [_as_json(v) for v in value]
    return value.item() if type(value).__module__ == "numpy" and hasattr(value, "item") else value


_PARSERS: dict[str, Callable[[_Fields], Message]] = {
    "report": _report,
    "detections": _detections,
    "team": _team,
    "status_request": _status_request,
    "status": _status,
}
