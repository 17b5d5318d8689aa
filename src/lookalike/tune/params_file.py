"""Parameter files, written by ``lookalike tune -o`` and read by ``--params``::

    {"tracker": "boxtrack", "params": {"high_score": 0.85, ...},
     "chosen_on": ["mot15/ADL-Rundle-6", ...], "criterion": "hota+idf1+mota",
     "trials": 60, "lookalike_version": "0.2.0"}

(extra keys kept)."""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from lookalike._version import __version__
from lookalike.io.rules import read_text
from lookalike.trackers.registry import make_tracker, tracker_names
from lookalike.tune.space import config_hints

REQUIRED = ("tracker", "params")


@dataclass(frozen=True)
class TunedParams:
    """A parameter file's content (``params``: JSON values, ``None``: a mechanism off; ``extra``: other keys)."""

    tracker: str
    params: dict[str, Any]
    chosen_on: list[str] = field(default_factory=list)
    criterion: str = ""
    trials: int = 0
    lookalike_version: str = ""
    extra: dict[str, Any] = field(default_factory=dict)

    def to_json(self) -> dict[str, Any]:
        """The file's JSON object."""
        return {"tracker": self.tracker, "params": self.params, "chosen_on": self.chosen_on,
                "criterion": self.criterion, "trials": self.trials, "lookalike_version": self.lookalike_version,
                **self.extra}


def save_params(path: str | Path, tracker: str, params: dict[str, Any], *, chosen_on: list[str],
                criterion: str, trials: int, **extra: Any) -> Path:
    """Write a parameter file (checked by :func:`check_params` first); returns its path."""
    check_params(tracker, params, source=str(path))
    content = TunedParams(tracker, dict(params), list(chosen_on), criterion, int(trials), __version__, dict(extra))
    from lookalike.io.outputs import write_atomic

    return write_atomic(path, json.dumps(content.to_json(), indent=2) + "\n")


def check_params(tracker: str, params: dict[str, Any], source: str = "params") -> None:
    """``ValueError`` naming ``source`` for an unknown tracker or parameter, or values the tracker refuses."""
    if tracker not in tracker_names():
        raise ValueError(f"{source}: unknown tracker {tracker!r}; registered: {', '.join(tracker_names())}")
    known = config_hints(tracker)
    unknown = sorted(set(params) - set(known))
    if unknown:
        raise ValueError(f"{source}: tracker {tracker!r} has no parameter(s) {', '.join(unknown)}; "
                         f"known: {', '.join(sorted(known))}")
    try:
        make_tracker(tracker, **params)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"{source}: tracker {tracker!r} refuses these parameters: {exc}") from None


def read_params(path: str | Path) -> TunedParams:
    """Read a parameter file; ``ValueError`` (naming the file) when it is not one."""
    p = Path(path)
    if p.is_dir():
        raise ValueError(f"{p}: is a folder, not a parameter file")
    try:
        data = json.loads(read_text(p))
    except FileNotFoundError:
        raise ValueError(f"{p}: parameter file not found") from None
    except (json.JSONDecodeError, RecursionError) as exc:
        raise ValueError(f"{p}: not a JSON parameter file ({str(exc)[:100]})") from None
    if not isinstance(data, dict) or any(k not in data for k in REQUIRED) or not isinstance(data["params"], dict):
        raise ValueError(f"{p}: expected a JSON object with 'tracker' and 'params' (written by `lookalike tune`)")
    chosen_on, trials = data.get("chosen_on", []), data.get("trials", 0)
    if not isinstance(chosen_on, list):
        raise ValueError(f"{p}: 'chosen_on' must be a list of sequence names, got {str(chosen_on)[:60]!r}")
    if isinstance(trials, bool) or not (isinstance(trials, int) or isinstance(trials, float) and trials.is_integer()):
        raise ValueError(f"{p}: 'trials' must be a whole number, got {str(trials)[:60]!r}")
    known = {"tracker", "params", "chosen_on", "criterion", "trials", "lookalike_version"}
    extra = {k: v for k, v in data.items() if k not in known}
    return TunedParams(str(data["tracker"]), dict(data["params"]), list(chosen_on), str(data.get("criterion", "")),
                       int(trials), str(data.get("lookalike_version", "")), extra)


def load_params(path: str | Path, tracker: str | None = None) -> dict[str, Any]:
    """The checked parameters in the file at ``path`` (``ValueError``: not for ``tracker``, or bad)."""
    content = read_params(path)
    if tracker is not None and content.tracker != tracker:
        raise ValueError(f"{path}: these parameters are for tracker {content.tracker!r}, not {tracker!r} "
                         f"(use -t {content.tracker})")
    check_params(content.tracker, content.params, source=str(path))
    return dict(content.params)


__all__ = ["TunedParams", "check_params", "load_params", "read_params", "save_params"]
