"""The diver bench (``lookalike bench divers``): the diver-tracking paper's Table 2 and Figure 5. Each rendered scenario
goes through a detector model (``sim`` or ``paper``) and its features are extracted once per feature set; every entry
(:data:`ENTRIES`) runs on identical detections."""

from __future__ import annotations

import dataclasses
from pathlib import Path
from typing import Any

import numpy as np

from lookalike.bench.tables import pyplot
from lookalike.eval.api import combine, evaluate_sequence
from lookalike.io.outputs import atomic_path
from lookalike.io.results import Results
from lookalike.sim.divers import SCENARIOS, detection_quality, scenario
from lookalike.sim.divers_paper import redraw, with_detections
from lookalike.sim.divers_run import diver_extractor, matched_thresholds, prepare_features, run_tracker
from lookalike.types.mot_table import MotTable

#: (label, tracker, features): the paper's three trackers plus the two cross-overs of features.
ENTRIES: tuple[tuple[str, str, str], ...] = (
    ("sort", "sort", "handcrafted"),
    ("deepsort/learned", "deepsort", "learned"),
    ("deepsort/handcrafted", "deepsort", "handcrafted"),
    ("diversort/handcrafted", "diversort", "handcrafted"),
    ("diversort/learned", "diversort", "learned"),
)
TRACKERS = tuple(label for label, _, _ in ENTRIES)
COLUMNS = ("Scenario", "Location", "DP", "DR", "Tracker", "IDF1", "IDP", "IDR", "IDSW", "Frag")


def entries(features: tuple[str, ...] = ("handcrafted", "learned")) -> tuple[tuple[str, str, str], ...]:
    """Entries ``(label, tracker, features)`` for feature sets ``handcrafted``, ``learned`` or ``FILE.onnx``
    (labelled by its stem): :data:`ENTRIES` for the default, else SORT, then deep SORT and DiverSORT with each."""
    if tuple(features) == ("handcrafted", "learned"):
        return ENTRIES
    if not features:
        raise ValueError("features: give at least one feature set")
    out = [("sort", "sort", features[0])]
    for tracker in ("deepsort", "diversort"):
        out += [(f"{tracker}/{Path(f).stem if f.lower().endswith('.onnx') else f}", tracker, f) for f in features]
    return tuple(out)


def diver_table(names: list[str] | None = None, trackers: tuple[str, ...] | None = None, frames: int | None = None,
                detections: str = "sim", seed: int = 0,
                features: tuple[str, ...] = ("handcrafted", "learned")) -> list[dict[str, Any]]:
    """Rows of Table 2 (:data:`COLUMNS`) for scenarios ``names`` (default all), entry labels ``trackers`` (default
    all), detector level ``detections`` and draw ``seed``, with an ALL row per entry."""
    known = entries(features)
    entry = {label: (tracker, feats) for label, tracker, feats in known}
    trackers = tuple(trackers) if trackers else tuple(label for label, _, _ in known)
    for t in trackers:
        if t not in entry:
            raise ValueError(f"unknown diver bench entry {t!r}; known: {', '.join(entry)}")
    chosen = [redraw(with_detections(scenario(n), detections), seed) for n in names] if names else \
        [redraw(with_detections(sc, detections), seed) for sc in SCENARIOS]
    if frames is not None:
        chosen = [dataclasses.replace(sc, frames=frames) for sc in chosen]
    extractors = {f: diver_extractor(f) for f in dict.fromkeys(entry[t][1] for t in trackers)}
    params = {t: matched_thresholds(extractors[entry[t][1]], entry[t][0]) for t in trackers}
    rows: list[dict[str, Any]] = []
    per_tracker: dict[str, list[dict[str, float]]] = {t: [] for t in trackers}
    det_counts = np.zeros(3)  # tp, fp, fn pooled
    for sc in chosen:
        prepared = prepare_features(sc, extractors)
        first = next(iter(prepared.values()))
        dp, dr = detection_quality(first.frames, first.gt)
        n_det = sum(len(f.detections) for f in first.frames)
        tp = dp * n_det
        det_counts += [tp, n_det - tp, tp / dr - tp if dr > 0 else len(first.gt)]
        gt = MotTable.from_rows(first.gt)
        for label in trackers:
            tracker, feats = entry[label]
            result, _ = run_tracker(tracker, prepared[feats].frames, **params[label])
            scores = evaluate_sequence(gt, MotTable.from_rows(result), metrics=["CLEAR", "Identity"],
                                       num_frames=len(first.frames))
            per_tracker[label].append(scores)
            rows.append(_row(sc.name, "pool" if sc.pool else "ocean", dp, dr, label, scores))
    tp, fp, fn = det_counts
    for label in trackers:
        rows.append(_row("ALL", "", tp / max(tp + fp, 1), tp / max(tp + fn, 1), label,
                         combine(per_tracker[label])))
    return rows


def _row(name: str, where: str, dp: float, dr: float, tracker: str, s: dict[str, float]) -> dict[str, Any]:
    return {
        "Scenario": name, "Location": where, "DP": round(100 * dp, 1), "DR": round(100 * dr, 1),
        "Tracker": tracker, "IDF1": round(100 * s["IDF1"], 1), "IDP": round(100 * s["IDP"], 1),
        "IDR": round(100 * s["IDR"], 1), "IDSW": int(s["IDSW"]), "Frag": int(s["Frag"]),
    }


def pearson(rows: list[dict[str, Any]]) -> dict[str, tuple[float, float]]:
    """Per entry, Pearson's r between DP and IDP over the scenarios and its p-value (NaN: < 3 or constant)."""
    from scipy.stats import pearsonr

    out: dict[str, tuple[float, float]] = {}
    for t in dict.fromkeys(r["Tracker"] for r in rows):
        pts = np.array([(r["DP"], r["IDP"]) for r in rows if r["Tracker"] == t and r["Scenario"] != "ALL"])
        if len(pts) < 3 or np.ptp(pts[:, 0]) == 0 or np.ptp(pts[:, 1]) == 0:
            out[t] = (float("nan"), float("nan"))
        else:
            res = pearsonr(pts[:, 0], pts[:, 1])
            out[t] = (float(res.statistic), float(res.pvalue))
    return out


def diver_results(tables: dict[str, list[dict[str, Any]]], frames: int, seed: int, command: str = "") -> Results:
    """:func:`diver_table`'s tables (one per detection level) as a results document: table ``divers``, dataset
    ``divers-<level>``, ALL rows ``combined``; Pearson r and p in the notes."""
    sequences = sorted({r["Scenario"] for rows in tables.values() for r in rows if r["Scenario"] != "ALL"})
    seeds = [redraw(scenario(n), seed).seed for n in sequences]
    doc = Results("bench divers", command=command, seeds=seeds, sequences=len(sequences) * len(tables),
                  frames=frames * len(sequences) * len(tables),
                  options={"detections": list(tables), "seed": seed, "frames_per_scenario": frames})
    notes: dict[str, Any] = {}
    for level, rows in tables.items():
        for r in rows:
            combined = r["Scenario"] == "ALL"
            metrics = {k.lower(): (r[k] / 100 if k in ("DP", "DR", "IDF1", "IDP", "IDR") else r[k])
                       for k in ("DP", "DR", "IDF1", "IDP", "IDR", "IDSW", "Frag")}
            doc.add("divers", dataset=f"divers-{level}", sequence=None if combined else r["Scenario"],
                    tracker=r["Tracker"], combined=combined, metrics=metrics,
                    info=None if combined else {"location": r["Location"]})
        notes[f"pearson_dp_idp_{level}"] = {t: {"r": rp[0], "p": rp[1]} for t, rp in pearson(rows).items()}
    doc.notes = notes
    return doc


def bar_chart(rows: list[dict[str, Any]], path: Path) -> Path:
    """IDF1 per scenario and tracker as a grouped bar chart PNG (the paper's Figure 5)."""
    plt = pyplot()
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
    ax.legend(fontsize=7)
    fig.tight_layout()
    with atomic_path(path) as tmp:
        fig.savefig(tmp, dpi=120, format="png")  # --png: a PNG whatever the name (matplotlib would add .png)
    plt.close(fig)
    return path


__all__ = ["COLUMNS", "ENTRIES", "TRACKERS", "bar_chart", "diver_results", "diver_table", "entries", "pearson"]
