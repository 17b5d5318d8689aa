"""The tracker protocol and the config convention every tracker follows."""

from __future__ import annotations

import dataclasses
import math
import numbers
import typing
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any, ClassVar, Protocol, runtime_checkable

import numpy as np

from lookalike.types import Frame, TrackSnapshot

NEEDS_APPEARANCE = "appearance features from the pixels: give the video with --video VIDEO"
NEEDS_ROBOTS = ("ground positions, headings and heading reports of robots (a `lookalike simulate` sequence, "
                "or --video V --pipeline robots --reports FILE)")


@runtime_checkable
class Tracker(Protocol):
    """A tracker consumes frames in time order and returns the tracks it reports for each. A tracker that needs more
    than boxes and scores says what in a class attribute ``needs`` (:data:`NEEDS_APPEARANCE`, :data:`NEEDS_ROBOTS`
    or a phrase of its own); the pipeline computes appearance features only for :data:`NEEDS_APPEARANCE`."""

    name: ClassVar[str]
    config: Any

    def update(self, frame: Frame) -> Sequence[TrackSnapshot]:
        """Process one frame; return the tracks reported for it (a :class:`~lookalike.types.Tracks`
        batch for the built-in trackers; any sequence of snapshots is accepted)."""
        ...

    def reset(self) -> None:
        """Forget all tracks and restart ids at 1."""
        ...


@dataclass(frozen=True)
class Range:
    """The allowed interval of a numeric parameter: ``low``/``high`` (None: unbounded), each end
    included unless ``low_open``/``high_open``. Shown as ``[0, 1]``, ``(0, inf)``."""

    low: float | None = None
    high: float | None = None
    low_open: bool = False
    high_open: bool = False

    def __contains__(self, value: object) -> bool:
        v = float(typing.cast(float, value))
        if self.low is not None and (v < self.low or (self.low_open and v == self.low)):
            return False
        return not (self.high is not None and (v > self.high or (self.high_open and v == self.high)))

    def __str__(self) -> str:
        low = "-inf" if self.low is None else _number(self.low)
        high = "inf" if self.high is None else _number(self.high)
        left = "(" if self.low_open or self.low is None else "["
        right = ")" if self.high_open or self.high is None else "]"
        return f"{left}{low}, {high}{right}"


def _number(value: float) -> str:
    return str(int(value)) if float(value).is_integer() else f"{value:g}"


# The ranges most parameters share.
UNIT = Range(0, 1)  # a fraction, a score, an IoU or a probability
PROBABILITY = Range(0, 1, low_open=True, high_open=True)  # strictly between 0 and 1 (a gate probability)
POSITIVE = Range(0, None, low_open=True)  # a scale: seconds, pixels, metres, a noise
NON_NEGATIVE = Range(0, None)
COUNT = Range(1, 10**9)  # frames, hits, slots: at least 1 (the cap keeps 64-bit arithmetic safe)
COUNT0 = Range(0, 10**9)  # a count that may be zero


def param(default: Any, doc: str, *, range: Range | tuple[float | None, float | None] | None = None,
          choices: Sequence[Any] | None = None) -> Any:
    """A config field with a default, a one-line description and the values it allows (all shown by
    ``lookalike trackers`` and checked by :func:`check_params`): ``range`` (a :class:`Range`, or
    ``(low, high)`` with both ends included; None: unbounded) or ``choices``. Numbers must be finite."""
    bounds = Range(*range) if isinstance(range, tuple) else range
    metadata: dict[str, Any] = {"doc": doc, "range": bounds,
                                "choices": tuple(choices) if choices is not None else None}
    return dataclasses.field(default=default, metadata=metadata)


_OWNERS: dict[type, str] = {}


def name_config(config_cls: type, tracker: str) -> None:
    """Record that ``config_cls`` is tracker ``tracker``'s config (its name starts error messages);
    called on registration."""
    _OWNERS.setdefault(config_cls, tracker)


def _owner(config_cls: type) -> str:
    return _OWNERS.get(config_cls, config_cls.__qualname__)


_Spec = tuple[str, Any, "Range | None", "tuple[Any, ...] | None"]
_SPECS: dict[type, tuple[_Spec, ...]] = {}


def field_specs(config_cls: type) -> tuple[_Spec, ...]:
    """Each field's name, type hint, range and choices (computed once per class)."""
    if config_cls not in _SPECS:
        hints = typing.get_type_hints(config_cls)
        _SPECS[config_cls] = tuple((f.name, hints[f.name], f.metadata.get("range"), f.metadata.get("choices"))
                                   for f in dataclasses.fields(config_cls))
    return _SPECS[config_cls]


def _type_name(kind: type) -> str:
    return {int: "an int", float: "a number", bool: "true or false", str: "text"}.get(kind, kind.__name__)


def check_value(owner: str, key: str, value: Any, hint: Any, bounds: Range | None = None,
                choices: Sequence[Any] | None = None) -> None:
    """``TypeError``/``ValueError`` in one line when ``value`` does not fit parameter ``key``: of the declared kind
    (``bool`` is not a number; an ``int`` is accepted for a ``float``), finite, inside ``bounds``, one of ``choices``,
    or None where the parameter is optional. ``owner``: the tracker's name."""
    args = typing.get_args(hint)
    optional = type(None) in args
    kinds = [a for a in args if a is not type(None)]
    kind = kinds[0] if kinds else hint
    where = f"tracker {owner!r}: {key}={value!r}"
    if value is None:
        if not optional:
            raise TypeError(f"{where} must be {_type_name(kind)}")
        return
    if kind in (int, float):
        ok = (numbers.Integral,) if kind is int else (numbers.Real,)
        if isinstance(value, (bool, np.bool_)) or not isinstance(value, ok):
            raise TypeError(f"{where} must be {_type_name(kind)}" + (" or None" if optional else ""))
        if not math.isfinite(float(value)):
            raise ValueError(f"{where} must be a finite number")
        if bounds is not None and value not in bounds:
            raise ValueError(f"{where} is out of range {bounds}")
    elif kind is bool:
        if not isinstance(value, (bool, np.bool_)):
            raise TypeError(f"{where} must be true or false")
    elif kind is str and not isinstance(value, str):
        raise TypeError(f"{where} must be text")
    if choices is not None and value not in choices:
        raise ValueError(f"{where} must be one of {', '.join(map(repr, choices))}")


def check_params(config: Any) -> None:
    """Check every field of the config dataclass against its :func:`param` declaration; the first bad one
    raises ``TypeError``/``ValueError`` in one line. Tracker configs call this in ``__post_init__``."""
    owner = _owner(type(config))
    for name, hint, bounds, choices in field_specs(type(config)):
        check_value(owner, name, getattr(config, name), hint, bounds, choices)


def check_positive(config: Any, *names: str, allow_zero: bool = False) -> None:
    """Raise ``ValueError`` naming the first config field that is not positive."""
    for name in names:
        value = getattr(config, name)
        if value is not None and (value < 0 or (value == 0 and not allow_zero)):
            bound = ">= 0" if allow_zero else "> 0"
            raise ValueError(f"{type(config).__name__}.{name} must be {bound}, got {value}")
