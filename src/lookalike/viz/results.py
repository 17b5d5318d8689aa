"""``eval``/``bench`` JSON outputs (results documents with a table ``ident``, ``divers`` or ``scores``, any other
results document's tables, or the older row lists and ``{tracker: {sequence: {metric: fraction}}}``) as tables and
charts (in %) of an :class:`HtmlReport`."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

from lookalike.io.results import SCHEMA_ID, is_fraction
from lookalike.io.rules import read_text
from lookalike.viz.plots import grouped_bar_chart
from lookalike.viz.report import HtmlReport

EVAL_COLUMNS = ("IDF1", "HOTA", "MOTA", "IDSW")
SIGNED_FRACTIONS = ("mota", "moda", "gap")  # fractions that may be negative, shown in % too


def _percent(metrics: dict[str, Any], key: str) -> float | None:
    value = metrics.get(key)
    return None if value is None else round(100 * float(value), 2)


def _from_schema(path: Path, data: dict[str, Any]) -> tuple[str, list[dict[str, Any]]]:
    """``(kind, display rows in %)`` of a results document."""
    tables = data.get("tables") or {}
    if tables.get("ident"):
        return "ident", [{"Setup": r["dataset"], "Tracker": r["tracker"],
                          "Success rate (%)": _percent(r["metrics"], "success_rate"),
                          "Localisation error (m)": r["metrics"].get("localisation_error_m"),
                          "Frames/s": r["metrics"].get("frames_per_s")} for r in tables["ident"]]
    if tables.get("divers"):
        rows = []
        levels = len({r["dataset"] for r in tables["divers"]}) > 1  # `bench divers --detections both`
        for r in tables["divers"]:
            m = r["metrics"]
            scenario = "ALL" if r["combined"] else r["sequence"]
            if levels:  # one bar and row per detection level, not the last level's over the first's
                scenario = f"{scenario} ({str(r['dataset']).removeprefix('divers-')})"
            row: dict[str, Any] = {"Scenario": scenario, "Tracker": r["tracker"]}
            row.update({k.upper(): _percent(m, k) for k in ("idf1", "hota", "mota", "idp", "idr") if k in m})
            row.update({k.upper(): m[k] for k in ("idsw",) if k in m})
            rows.append(row)
        return "divers", rows
    if tables.get("scores"):
        out = []
        for r in tables["scores"]:
            m = r["metrics"]
            row = {"Tracker": r["tracker"], "Sequence": "COMBINED" if r["combined"] else r["sequence"]}
            row.update({k.upper(): _percent(m, k) for k in ("idf1", "hota", "mota") if k in m})
            if "idsw" in m:
                row["IDSW"] = m["idsw"]
            out.append(row)
        return "eval", out
    rows = _any_tables(tables)
    if rows:
        return "tables", rows
    raise ValueError(f"results: {path} has no table rows (see `lookalike report --help`)")


def _any_tables(tables: dict[str, Any]) -> list[dict[str, Any]]:
    """The rows of any other bench's tables (``bench real``, ``pixels``, ``shuffle``, ``recovery``, ``ident
    --lengths``): table, data set, sequence (where one is named), tracker and every metric, fractions in %."""
    rows = []
    for name, table in tables.items():
        named = any(r["sequence"] is not None for r in table)
        for r in table:
            row: dict[str, Any] = {"Table": name, "Dataset": r["dataset"] or "all"}
            if named:
                row["Sequence"] = r["sequence"] or "all"
            row["Tracker"] = r["tracker"]
            for key, value in r["metrics"].items():
                percent = is_fraction(key) or key in SIGNED_FRACTIONS
                row[f"{key} (%)" if percent else key] = (
                    "" if value is None else round(100 * float(value), 2) if percent else value)
            rows.append(row)
    return rows


def load_results(path: Path | str) -> tuple[str, list[dict[str, Any]]]:
    """``(kind, rows)`` of a results file; kind is ``"ident"``, ``"divers"``, ``"eval"`` or ``"tables"`` (any other
    results document: one table per ``Table``, no chart)."""
    p = Path(path)
    if not p.is_file():
        raise ValueError(f"results: {'a folder, not a file:' if p.is_dir() else 'no such file'} {p}")
    try:
        data = json.loads(read_text(p))
    except json.JSONDecodeError as exc:
        raise ValueError(f"results: {p} is not JSON ({exc})") from None
    except RecursionError:
        raise ValueError(f"results: {p} is nested too deeply to be an eval or bench JSON output") from None
    try:
        return _interpret(p, data)
    except (TypeError, AttributeError, KeyError, IndexError, OverflowError, ValueError) as exc:  # a wrong type
        if isinstance(exc, ValueError) and str(exc).startswith("results:"):
            raise
        raise ValueError(f"results: {p}: unexpected content ({type(exc).__name__}: {str(exc)[:80]})") from None


def _interpret(p: Path, data: Any) -> tuple[str, list[dict[str, Any]]]:
    """:func:`load_results` of the parsed JSON ``data`` of ``p``."""
    if isinstance(data, dict) and data.get("schema") == SCHEMA_ID:
        return _from_schema(p, data)
    if isinstance(data, list) and data and all(isinstance(r, dict) for r in data):
        if "Setup" in data[0] and "Success rate (%)" in data[0]:
            return "ident", data
        if "Scenario" in data[0] and "IDF1" in data[0]:
            return "divers", data
    if isinstance(data, dict) and data and all(isinstance(v, dict) for v in data.values()):
        rows = []
        for tracker, per_seq in data.items():
            for seq, values in per_seq.items():
                present = [c for c in EVAL_COLUMNS if isinstance(values, dict) and c in values]
                if not present:
                    raise ValueError(f"results: {p}: {tracker}/{seq} has none of {', '.join(EVAL_COLUMNS)}")
                rows.append({"Tracker": tracker, "Sequence": seq,
                             **{c: (int(values[c]) if c == "IDSW" else round(100 * float(values[c]), 2))
                                for c in present}})
        if rows:
            return "eval", rows
    raise ValueError(f"results: {p} is not an eval or bench JSON output (see `lookalike report --help`)")


def add_results(report: HtmlReport, kind: str, rows: list[dict[str, Any]], charts_dir: Path, stem: str,
                title: str | None = None) -> list[Path]:
    """A section with the rows' table and a bar chart (PNG written in ``charts_dir``, then embedded)."""
    if kind == "ident":
        report.heading(title or "Robot identification")
        report.table(rows)
        chart = grouped_bar_chart(charts_dir / f"{stem}.png", rows, "Setup", "Tracker", "Success rate (%)",
                                  title="Identification success rate per set-up")
        report.image(chart, "Identification success rate (%) per set-up and identifier")
    elif kind == "divers":
        report.heading(title or "Diver tracking")
        report.table(rows)
        chart = grouped_bar_chart(charts_dir / f"{stem}.png", rows, "Scenario", "Tracker", "IDF1",
                                  ylabel="IDF1 (%)", title="IDF1 per scenario")
        report.image(chart, "IDF1 (%) per scenario and tracker")
    elif kind == "eval":
        report.heading(title or "Evaluation (values in %)")
        report.table(rows)
        metric = next((c for c in EVAL_COLUMNS if c in rows[0] and c != "IDSW"), None)
        if metric is None:
            return []
        chart = grouped_bar_chart(charts_dir / f"{stem}.png", rows, "Sequence", "Tracker", metric,
                                  ylabel=f"{metric} (%)", ylim=None, title=f"{metric} per sequence")
        report.image(chart, f"{metric} (%) per sequence and tracker")
    elif kind == "tables":
        for name in dict.fromkeys(r["Table"] for r in rows):
            report.heading(f"{title}: {name}" if title else name)
            mine = [{k: v for k, v in r.items() if k != "Table"} for r in rows if r["Table"] == name]
            report.table(mine, list(dict.fromkeys(k for r in mine for k in r)))
        return []
    else:
        raise ValueError(f"kind: unknown results kind {kind!r}; known: ident, divers, eval, tables")
    return [chart]
