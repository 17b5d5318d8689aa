"""Farazi and Behnke (IROS 2017): identifier variants for ``bench ident``, the paper's Table I and the margins over
Kalman-HA."""

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


def resolve_identifier(name: str) -> tuple[str, dict[str, Any]]:
    """The registered tracker and extra parameters behind identifier ``name`` (a variant or a tracker)."""
    base, extra = IDENT_VARIANTS.get(name, (name, {}))
    return base, dict(extra)


def margin_rows(rows: Sequence[dict[str, Any]], setups: Sequence[str], labels: Sequence[str],
                baseline: str = "kalman_ha") -> list[dict[str, Any]]:
    """Per set-up and LSTM row of ``bench ident``, its margin (points) over ``baseline`` beside the paper's."""
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
                        "Paper's margin (points)": round(paper_margin, 1)})
    return out


__all__ = ["IDENT_VARIANTS", "PAPER_TABLE1", "margin_rows", "resolve_identifier"]
