"""Search spaces: parameter name -> :class:`Dim` (a range, log for scale-like numbers, or choices; ``optional``: also
``None``) or a fixed value. ``sort`` and ``boxtrack`` have declared spaces, other trackers :func:`generic_space`; the
JSON form (:func:`space_from_json`)::

    {"high_score": {"low": 0.5, "high": 0.99},
     "max_age_s": {"low": 0.25, "high": 4, "log": true},
     "n_init": {"low": 1, "high": 5, "type": "int"},
     "clutter_factor": {"low": 0.5, "high": 8, "log": true, "optional": true},
     "low_score": 0.1}

(a bare value fixes the parameter)."""

from __future__ import annotations

import json
import math
import os
import typing
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from lookalike.trackers.base import Range
from lookalike.trackers.registry import tracker_class, tracker_parameters

KINDS = ("float", "int", "choice")
NOT_SEARCHED = ("frame_interval_s", "max_targets")  # set by the data (frame rate, a known count), never tuned


@dataclass(frozen=True)
class Dim:
    """One searched parameter: ``"float"``/``"int"`` in ``[low, high]`` or ``"choice"``; ``optional`` adds ``None``."""

    kind: str
    low: float | None = None
    high: float | None = None
    log: bool = False
    choices: tuple[Any, ...] = ()
    optional: bool = False

    def __post_init__(self) -> None:
        if self.kind not in KINDS:
            raise ValueError(f"kind: expected one of {KINDS}, got {self.kind!r}")
        if self.kind == "choice":
            if not self.choices:
                raise ValueError("a choice dimension needs at least one choice")
            return
        if self.low is None or self.high is None or not self.low <= self.high:
            raise ValueError(f"range: expected low <= high, got [{self.low}, {self.high}]")
        if self.log and self.low <= 0:
            raise ValueError(f"a log-scale range needs low > 0, got {self.low}")

    def to_json(self) -> dict[str, Any]:
        """The JSON form read back by :func:`space_from_json`."""
        if self.kind == "choice":
            return {"choices": list(self.choices)}
        out: dict[str, Any] = {"low": self.low, "high": self.high, "type": self.kind}
        if self.log:
            out["log"] = True
        if self.optional:
            out["optional"] = True
        return out


Space = dict[str, Any]  # name -> Dim, or a fixed value


def _f(low: float, high: float, log: bool = False, optional: bool = False) -> Dim:
    return Dim("float", low, high, log=log, optional=optional)


def _i(low: int, high: int, log: bool = False, optional: bool = False) -> Dim:
    return Dim("int", low, high, log=log, optional=optional)


# The default spaces: ranges bracket the defaults widely; closed-set parameters are left out.
DEFAULT_SPACES: dict[str, Space] = {
    "sort": {
        "max_age": _i(1, 30, log=True),
        "min_hits": _i(1, 5),
        "iou_threshold": _f(0.1, 0.6),
    },
    "boxtrack": {
        "high_score": _f(0.5, 0.99),
        "low_score": _f(0.01, 0.5, log=True),
        "birth_score": _f(0.5, 0.99),
        "clutter_factor": _f(0.5, 8.0, log=True, optional=True),
        "high_match_ratio": _f(0.2, 0.95, optional=True),
        "match_iou": _f(0.05, 0.6),
        "n_init": _i(1, 5),
        "max_age_s": _f(0.25, 4.0, log=True),
        "reid_scale": _f(1.1, 3.0, log=True),
    },
}

_FRACTION_WORDS = ("score", "iou", "quantile", "ratio", "prob", "rate", "fraction")


def config_hints(tracker: str) -> dict[str, Any]:
    """The annotations of ``tracker``'s ``Config`` fields (name -> type)."""
    cls: Any = tracker_class(tracker)
    return typing.get_type_hints(cls.Config)


def _base_type(hint: Any) -> tuple[Any, bool]:
    """``(type, optional)`` of a config field's annotation (``float | None`` -> ``(float, True)``)."""
    args = [a for a in typing.get_args(hint) if a is not type(None)]
    if args:
        return args[0], len(args) < len(typing.get_args(hint))
    return hint, False


def generic_space(tracker: str) -> Space:
    """A space from ``tracker``'s defaults: booleans both ways, a positive default ``d`` log-uniform in ``[d/3, 3d]``
    (fractions at most 1, integers at least 1) within its declared range; others not searched."""
    hints = config_hints(tracker)
    out: Space = {}
    for p in tracker_parameters(tracker):
        base, _ = _base_type(hints[p.name])
        d = p.default
        if p.name in NOT_SEARCHED or d is None:
            continue
        if base is bool:
            out[p.name] = Dim("choice", choices=(False, True))
        elif base is int and d > 0:
            low_i, high_i = _inside(p.range, max(1, d // 3), max(3 * d, d + 2), d)
            out[p.name] = _i(int(math.ceil(low_i)), int(math.floor(high_i)), log=True)
        elif base is float and d > 0:
            high = 3 * d
            if d <= 1 and any(w in p.name for w in _FRACTION_WORDS):
                high = min(high, 1.0)
            out[p.name] = _f(*_inside(p.range, d / 3, high, d), log=True)
    return out


def _inside(bounds: Range | None, low: float, high: float, default: float) -> tuple[float, float]:
    """``[low, high]`` clipped to the parameter's declared range (an open end: halfway from the default)."""
    if bounds is None:
        return low, high
    if bounds.low is not None and low <= bounds.low:
        low = (bounds.low + default) / 2 if bounds.low_open else bounds.low
    if bounds.high is not None and high >= bounds.high:
        high = (bounds.high + default) / 2 if bounds.high_open else bounds.high
    return low, high


def default_space(tracker: str) -> Space:
    """The declared space of ``tracker`` (its parameters only), else :func:`generic_space`."""
    if tracker not in DEFAULT_SPACES:
        return generic_space(tracker)
    known = {p.name for p in tracker_parameters(tracker)}
    return {k: v for k, v in DEFAULT_SPACES[tracker].items() if k in known}


def read_space(path: str | os.PathLike[str], tracker: str) -> Space:
    """The search space in the JSON file ``path`` (:func:`space_from_json`); ``ValueError`` naming the file for one
    that is not JSON (or nested too deeply to be a space)."""
    from lookalike.io.rules import read_text

    try:
        spec = json.loads(read_text(path))
    except (json.JSONDecodeError, RecursionError) as exc:
        raise ValueError(f"{path}: not a JSON search space ({str(exc)[:100]})") from None
    return space_from_json(spec, tracker)


def space_from_json(spec: Mapping[str, Any], tracker: str) -> Space:
    """A space from its JSON form (module docstring); ``ValueError`` naming an unknown parameter or bad entry."""
    if not isinstance(spec, Mapping):
        raise ValueError(f"space: expected a JSON object {{parameter: range}}, got a {type(spec).__name__}")
    hints = config_hints(tracker)
    out: Space = {}
    for name, entry in spec.items():
        if name not in hints:
            raise ValueError(f"space: tracker {tracker!r} has no parameter {name!r}; known: {sorted(hints)}")
        if not isinstance(entry, Mapping):
            out[name] = entry  # a fixed value
            continue
        unknown = set(entry) - {"low", "high", "log", "type", "choices", "optional"}
        if unknown:
            raise ValueError(f"space: {name}: unknown key(s) {sorted(unknown)}")
        try:
            if "choices" in entry:
                out[name] = Dim("choice", choices=tuple(entry["choices"]))
                continue
            base, _ = _base_type(hints[name])
            kind = entry.get("type", "int" if base is int else "float")
            out[name] = Dim(kind, float(entry["low"]), float(entry["high"]), log=bool(entry.get("log", False)),
                            optional=bool(entry.get("optional", False)))
        except (KeyError, TypeError, ValueError) as exc:
            raise ValueError(f"space: {name}: {exc}") from None
    return out


def space_to_json(space: Space) -> dict[str, Any]:
    """The JSON form of ``space`` (module docstring)."""
    return {k: (v.to_json() if isinstance(v, Dim) else v) for k, v in space.items()}


def searched(space: Space) -> dict[str, Dim]:
    """The dimensions of ``space`` that are searched (not fixed)."""
    return {k: v for k, v in space.items() if isinstance(v, Dim)}


def fixed(space: Space) -> dict[str, Any]:
    """The fixed values of ``space``."""
    return {k: v for k, v in space.items() if not isinstance(v, Dim)}


def suggest(trial: Any, space: Space) -> dict[str, Any]:
    """Tracker parameters drawn by an Optuna ``trial`` from ``space`` (optional ones as ``<name>:on`` first)."""
    params = dict(fixed(space))
    for name, dim in searched(space).items():
        if dim.optional and not trial.suggest_categorical(f"{name}:on", [True, False]):
            params[name] = None
        elif dim.kind == "choice":
            params[name] = trial.suggest_categorical(name, list(dim.choices))
        elif dim.kind == "int":
            params[name] = trial.suggest_int(name, int(dim.low), int(dim.high), log=dim.log)  # type: ignore[arg-type]
        else:
            params[name] = trial.suggest_float(name, float(dim.low), float(dim.high), log=dim.log)  # type: ignore[arg-type]
    return params


def trial_values(params: Mapping[str, Any], space: Space) -> dict[str, Any]:
    """The Optuna trial parameters (:func:`suggest`'s names) that give tracker ``params``."""
    out: dict[str, Any] = {}
    for name, dim in searched(space).items():
        if name not in params:
            continue
        value = params[name]
        if dim.optional:
            out[f"{name}:on"] = value is not None
        if value is not None:
            out[name] = value
    return out


def sample(space: Space, rng: np.random.Generator) -> dict[str, Any]:
    """Tracker parameters drawn (log-)uniformly from ``space`` with ``rng``, optional ones off with p = 1/2."""
    params = dict(fixed(space))
    for name, dim in searched(space).items():
        if dim.optional and rng.random() < 0.5:
            params[name] = None
        elif dim.kind == "choice":
            params[name] = dim.choices[int(rng.integers(len(dim.choices)))]
        elif dim.kind == "int":
            lo, hi = int(dim.low), int(dim.high)  # type: ignore[arg-type]
            if dim.log:
                params[name] = min(hi, int(math.floor(math.exp(rng.uniform(math.log(lo), math.log(hi + 1))))))
            else:
                params[name] = int(rng.integers(lo, hi + 1))
        else:
            lo_f, hi_f = float(dim.low), float(dim.high)  # type: ignore[arg-type]
            v = math.exp(rng.uniform(math.log(lo_f), math.log(hi_f))) if dim.log else rng.uniform(lo_f, hi_f)
            params[name] = float(v)
    return params


def grid(dim: Dim, points: int = 5) -> list[Any]:
    """``points`` values spread over ``dim`` (or its choices), and ``None`` when optional."""
    if dim.kind == "choice":
        values = list(dim.choices)
    else:
        lo, hi = float(dim.low), float(dim.high)  # type: ignore[arg-type]
        raw = np.geomspace(lo, hi, points) if dim.log else np.linspace(lo, hi, points)
        values = list(dict.fromkeys(int(round(v)) if dim.kind == "int" else float(v) for v in raw))
    return values + [None] if dim.optional else values


__all__ = ["DEFAULT_SPACES", "Dim", "NOT_SEARCHED", "Space", "default_space", "fixed", "generic_space", "grid",
           "read_space", "sample", "searched", "space_from_json", "space_to_json", "suggest", "trial_values"]
