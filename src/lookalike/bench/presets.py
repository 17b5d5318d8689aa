"""Parameter presets of the benches (``presets/*.json``, each with ``chosen_on`` and ``search``); they feed only the
"tuned on this data" rows."""

from __future__ import annotations

import json
from functools import cache
from importlib import resources
from typing import Any

PRESET_FILES = ("boxtrack",)


@cache
def load_preset(name: str) -> dict[str, Any]:
    """The parsed preset file ``presets/<name>.json`` (cached; do not modify the result)."""
    if name not in PRESET_FILES:
        raise ValueError(f"preset: unknown preset {name!r}; known: {', '.join(PRESET_FILES)}")
    text = resources.files("lookalike.bench").joinpath("presets").joinpath(f"{name}.json").read_text()
    return dict(json.loads(text))


def chosen_on(preset: str, dataset: str) -> str:
    """What the parameters of ``preset`` for ``dataset`` were chosen on ("" when there are none)."""
    data = load_preset(preset)
    for group in ("sequences", "tuned"):
        entry = data.get(group, {}).get(dataset)
        if entry is not None:
            return str(entry["chosen_on"])
    return ""


def _sequence_params() -> dict[str, dict[str, dict[str, dict[str, Any]]]]:
    boxtrack = load_preset("boxtrack")
    return {d: {boxtrack["tracker"]: {s: dict(p) for s, p in e["params"].items()}}
            for d, e in boxtrack["sequences"].items()}


# dataset -> tracker -> sequence -> parameters chosen on its first half (boxtrack.json "sequences"; tuned row only)
SEQUENCE_PARAMS: dict[str, dict[str, dict[str, dict[str, Any]]]] = _sequence_params()
# dataset -> tracker -> parameters chosen on that dataset for the "tuned on this data" row only (boxtrack.json "tuned")
TUNED_PARAMS: dict[str, dict[str, dict[str, Any]]] = {
    d: {load_preset("boxtrack")["tracker"]: dict(e["params"])}
    for d, e in load_preset("boxtrack").get("tuned", {}).items()}

__all__ = ["PRESET_FILES", "SEQUENCE_PARAMS", "TUNED_PARAMS", "chosen_on", "load_preset"]
