"""The diver bench (``lookalike bench divers``): the paper's Table 2 and Figure 5 on the rendered diver scenarios.

Every scenario is rendered, passed through the detector model, and its detections' appearance
features are extracted once (the extractor standardised on the validation scenarios); SORT, the
deep SORT style tracker and diver SORT then run on the identical detections. The table gives the
detector's DP/DR and each tracker's IDF1, IDP, IDR, IDSW and Frag (percentages and counts), with
an ALL row per tracker (counts pooled over scenarios).
"""

from __future__ import annotations

import dataclasses
from pathlib import Path
from typing import Any

import numpy as np

from lookalike.eval.api import combine, evaluate_sequence
from lookalike.sim.divers import SCENARIOS, detection_quality, scenario
from lookalike.sim.divers_run import fit_diver_features, prepare, run_tracker
from lookalike.types.mot_table import MotTable

TRACKERS = ("sort", "deepsort", "diversort")
COLUMNS = ("Scenario", "Location", "DP", "DR", "Tracker", "IDF1", "IDP", "IDR", "IDSW", "Frag")


def diver_table(names: list[str] | None = None, trackers: tuple[str, ...] = TRACKERS,
                frames: int | None = None) -> list[dict[str, Any]]:
    """Rows of Table 2 (keys :data:`COLUMNS`) for scenarios ``names`` (default: all test scenarios)."""
    chosen = [scenario(n) for n in names] if names else list(SCENARIOS)
    if frames is not None:
        chosen = [dataclasses.replace(sc, frames=frames) for sc in chosen]
    extractor = fit_diver_features()
    rows: list[dict[str, Any]] = []
    per_tracker: dict[str, list[dict[str, float]]] = {t: [] for t in trackers}
    det_counts = np.zeros(3)  # tp, fp, fn pooled
    for sc in chosen:
        prepared = prepare(sc, extractor)
        dp, dr = detection_quality(prepared.frames, prepared.gt)
        n_det = sum(len(f.detections) for f in prepared.frames)
        tp = dp * n_det
        det_counts += [tp, n_det - tp, tp / dr - tp if dr > 0 else len(prepared.gt)]
        gt = MotTable.from_rows(prepared.gt)
        for name in trackers:
            result, _ = run_tracker(name, prepared.frames)
            scores = evaluate_sequence(gt, MotTable.from_rows(result), metrics=["CLEAR", "Identity"],
                                       num_frames=len(prepared.frames))
            per_tracker[name].append(scores)
            rows.append(_row(sc.name, "pool" if sc.pool else "ocean", dp, dr, name, scores))
    tp, fp, fn = det_counts
    for name in trackers:
        rows.append(_row("ALL", "", tp / max(tp + fp, 1), tp / max(tp + fn, 1), name, combine(per_tracker[name])))
    return rows


def _row(name: str, where: str, dp: float, dr: float, tracker: str, s: dict[str, float]) -> dict[str, Any]:
    return {
        "Scenario": name, "Location": where, "DP": round(100 * dp, 1), "DR": round(100 * dr, 1),
        "Tracker": tracker, "IDF1": round(100 * s["IDF1"], 1), "IDP": round(100 * s["IDP"], 1),
        "IDR": round(100 * s["IDR"], 1), "IDSW": int(s["IDSW"]), "Frag": int(s["Frag"]),
    }


def bar_chart(rows: list[dict[str, Any]], path: Path) -> Path:
    """IDF1 per scenario and tracker as a grouped bar chart PNG (the paper's Figure 5)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    scenarios = list(dict.fromkeys(r["Scenario"] for r in rows))
    trackers = list(dict.fromkeys(r["Tracker"] for r in rows))
    value = {(r["Scenario"], r["Tracker"]): r["IDF1"] for r in rows}
    x = np.arange(len(scenarios))
    width = 0.8 / len(trackers)
    fig, ax = plt.subplots(figsize=(max(6, 1.2 * len(scenarios)), 4))
    for i, t in enumerate(trackers):
        ax.bar(x + (i - (len(trackers) - 1) / 2) * width, [value.get((s, t), 0) for s in scenarios], width, label=t)
    ax.set_xticks(x, scenarios, rotation=30, ha="right", fontsize=8)
    ax.set_ylabel("IDF1 (%)")
    ax.set_ylim(0, 100)
    ax.legend()
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path


__all__ = ["COLUMNS", "TRACKERS", "bar_chart", "diver_table"]
