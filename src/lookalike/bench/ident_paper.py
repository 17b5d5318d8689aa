"""Farazi and Behnke's own figures (IROS 2017) beside ours: identifier variants for ``bench ident`` (``lstm-paper``: the
paper's input protocol decoded per slot; ``lstm-lowpass``: the paper's low-pass localiser), the paper's Tables I–III and
the margins over Kalman-HA (the only like-for-like comparison: the simulators differ)."""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

IDENT_VARIANTS: dict[str, tuple[str, dict[str, Any]]] = {
    "lstm-paper": ("lstm", {"protocol": "paper", "one_to_one": False}),
    "lstm-paper-lowpass": ("lstm", {"protocol": "paper", "one_to_one": False, "localiser": "lowpass"}),
    "lstm-lowpass": ("lstm", {"localiser": "lowpass"}),
}

# Farazi and Behnke, Table I: success rate (%) on its synthetic dataset, per set-up.
PAPER_TABLE1: dict[str, dict[str, float]] = {
    "m3n2": {"human": 94.3, "kalman_ha": 75.6, "lstm": 96.2},
    "m5n3": {"human": 86.3, "kalman_ha": 72.2, "lstm": 87.1},
    "m10n7": {"human": 67.3, "kalman_ha": 53.1, "lstm": 66.5},
}
# Farazi and Behnke, Table II: average localisation error (m) on its real dataset.
PAPER_TABLE2: dict[str, float] = {"kalman_ha": 0.67, "kalman_ha2": 0.30, "jpda": 0.29, "lstm": 0.22}
# Farazi and Behnke, Table III: success rate (%) on its real dataset by sequence length (frames; 0 = the total, 3140).
PAPER_TABLE3: dict[str, dict[int, float]] = {
    "kalman_ha": {200: 73.2, 400: 75.5, 800: 72.1, 0: 73.8},
    "kalman_ha2": {200: 87.2, 400: 84.0, 800: 86.3, 0: 85.5},
    "jpda": {200: 87.1, 400: 84.6, 800: 85.6, 0: 86.3},
    "lstm": {200: 89.8, 400: 90.3, 800: 92.4, 0: 91.1},
}


def resolve_identifier(name: str) -> tuple[str, dict[str, Any]]:
    """The registered tracker and extra parameters behind identifier ``name`` (a variant or a tracker)."""
    base, extra = IDENT_VARIANTS.get(name, (name, {}))
    return base, dict(extra)


def margin_rows(rows: Sequence[dict[str, Any]], setups: Sequence[str], labels: Sequence[str],
                baseline: str = "kalman_ha") -> list[dict[str, Any]]:
    """Per set-up and LSTM row of ``rows`` (``bench ident`` rows), the margin in points of its success
    rate over ``baseline`` on the same sequences, beside the paper's margin of its LSTM over Kalman-HA."""
    out = []
    for setup, label in zip(setups, labels):
        mine = {r["Tracker"]: r["Success rate (%)"] for r in rows if r["Setup"] == label}
        if baseline not in mine:
            continue
        paper = PAPER_TABLE1.get(setup, {})
        paper_margin = paper["lstm"] - paper["kalman_ha"] if paper else math.nan
        for name, rate in mine.items():
            if resolve_identifier(name)[0] != "lstm" or not isinstance(rate, (int, float)):
                continue  # not an LSTM, or no figure (weights not trained for the set-up)
            out.append({"Setup": label, "Identifier": name, "Success rate (%)": rate,
                        f"{baseline} (%)": mine[baseline], "Margin (points)": round(rate - mine[baseline], 2),
                        "Seed A's margin (points)": round(paper_margin, 1)})
    return out


__all__ = ["IDENT_VARIANTS", "PAPER_TABLE1", "PAPER_TABLE2", "PAPER_TABLE3", "margin_rows", "resolve_identifier"]
