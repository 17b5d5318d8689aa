"""Parameter files: a tracker's chosen parameters and what they were chosen on.

The JSON written by ``lookalike tune -o params.json`` and read by ``lookalike track --params`` and
``lookalike bench real --params``::

    {"tracker": "boxtrack", "params": {"high_score": 0.85, ...},
     "chosen_on": ["mot15/ADL-Rundle-6", ...], "criterion": "hota+idf1+mota",
     "trials": 60, "lookalike_version": "0.1.0"}

Extra keys (``score``, ``sampler``, ``folds``...) are kept but not needed.
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from lookalike.trackers.registry import make_tracker, tracker_names
from lookalike.tune.space import config_hints

REQUIRED = ("tracker", "params")


@dataclass(frozen=True)
class TunedParams:
    """A parameter file's content.

    Attributes:
        tracker: registered tracker name.
        params: parameter name -> value (JSON types; ``None`` switches a mechanism off).
        chosen_on: the sequences (``dataset/name``) the parameters were chosen on.
        criterion: what was maximised (e.g. ``"hota+idf1+mota"``).
        trials: number of trials of the study.
        lookalike_version: the version that chose them.
        extra: any other keys of the file."""

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


def _version() -> str:
    from lookalike import __version__

    return str(__version__)


def save_params(path: str | Path, tracker: str, params: dict[str, Any], *, chosen_on: list[str],
                criterion: str, trials: int, **extra: Any) -> Path:
    """Write a parameter file (checked by :func:`check_params` first); returns its path."""
    check_params(tracker, params, source=str(path))
    content = TunedParams(tracker, dict(params), list(chosen_on), criterion, int(trials), _version(), dict(extra))
    from lookalike.io.outputs import write_atomic

    return write_atomic(path, json.dumps(content.to_json(), indent=2) + "\n")


def check_params(tracker: str, params: dict[str, Any], source: str = "params") -> None:
    """Raise ``ValueError`` naming ``source`` when ``tracker`` is not registered, a parameter is
    unknown, or the tracker refuses the values."""
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
    try:
        data = json.loads(p.read_text())
    except FileNotFoundError:
        raise ValueError(f"{p}: parameter file not found") from None
    except json.JSONDecodeError as exc:
        raise ValueError(f"{p}: not a JSON parameter file ({exc})") from None
    if not isinstance(data, dict) or any(k not in data for k in REQUIRED) or not isinstance(data["params"], dict):
        raise ValueError(f"{p}: expected a JSON object with 'tracker' and 'params' (written by `lookalike tune`)")
    known = {"tracker", "params", "chosen_on", "criterion", "trials", "lookalike_version"}
    return TunedParams(str(data["tracker"]), dict(data["params"]), list(data.get("chosen_on", [])),
                       str(data.get("criterion", "")), int(data.get("trials", 0)),
                       str(data.get("lookalike_version", "")), {k: v for k, v in data.items() if k not in known})


def load_params(path: str | Path, tracker: str | None = None) -> dict[str, Any]:
    """The parameters in the file at ``path``, checked against the tracker they are for.

    ``tracker``: the tracker the caller will build; a file written for another tracker is refused. Raises ``ValueError``
    with a message naming the file and what is wrong (not found, not a parameter file, another tracker, unknown tracker
    or parameter, values the tracker refuses)."""
    content = read_params(path)
    if tracker is not None and content.tracker != tracker:
        raise ValueError(f"{path}: these parameters are for tracker {content.tracker!r}, not {tracker!r} "
                         f"(use -t {content.tracker})")
    check_params(content.tracker, content.params, source=str(path))
    return dict(content.params)


__all__ = ["TunedParams", "check_params", "load_params", "read_params", "save_params"]
