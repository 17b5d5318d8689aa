"""One results schema for every ``--json``: ``{"schema": "lookalike-results/1", "header": {...}, "tables": {name:
[row, ...]}}`` (``results.schema.json``); a row holds ``dataset``, ``sequence`` (None across sequences), ``tracker``,
``combined``, ``metrics`` (machine keys, :func:`metric_key`; fractions in [0, 1]; NaN as ``null``), and optional
``info`` and ``error``. Usage: ``doc = Results("bench divers", ...)``; ``doc.add("divers", dataset=..., tracker=...,
metrics={"idf1": 0.81})``; ``doc.write(path)``."""

from __future__ import annotations

import datetime as _dt
import json
import math
import re
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from lookalike._optional import needs

SCHEMA_ID = "lookalike-results/1"
SCHEMA_PATH = Path(__file__).with_name("results.schema.json")
KEY_PATTERN = re.compile(r"^[a-z][a-z0-9_]*$")
#: Metrics that are fractions in [0, 1], as are ``success_rate_*`` and HOTA's per-alpha values.
FRACTIONS = frozenset({
    "success_rate", "hota", "deta", "assa", "loca", "idf1", "idp", "idr", "motp", "dp", "dr",
    "recall", "precision",
})
_ALPHA_FRACTION = re.compile(
    r"^((hota|deta|assa|loca|detre|detpr|assre|asspr|rhota)_([0-9]+|auc)|success_rate_[a-z0-9_]+)$")
_UNITS = {"(m)": "_m", "(s)": "_s", "(deg)": "_deg", "(px)": "_px"}


def lookalike_version() -> str:
    """The version of the lookalike that runs (``lookalike.__version__``, which the package metadata also reads)."""
    from lookalike._version import __version__

    return __version__


def metric_key(name: str) -> str:
    """A machine key for a printed or TrackEval metric name: ``"HOTA___AUC"`` -> ``"hota_auc"``, ``"Localisation
    error (m)"`` -> ``"localisation_error_m"``, ``"Frames/s"`` -> ``"frames_per_s"``, ``"Success rate (%)"`` ->
    ``"success_rate"``."""
    text = name.strip()
    for unit, suffix in _UNITS.items():
        if text.endswith(unit):
            text = text[: -len(unit)] + suffix
    text = re.sub(r"\((%|pp)\)$", "", text).replace("/s", " per s")
    key = re.sub(r"[^a-z0-9]+", "_", text.lower()).strip("_")
    if not key or not key[0].isalpha():
        key = f"m_{key}"
    return key


def is_fraction(key: str) -> bool:
    """Whether metric ``key`` is a fraction in [0, 1]."""
    return key in FRACTIONS or bool(_ALPHA_FRACTION.match(key))


def _number(key: str, value: Any) -> float | int | None:
    if value is None:
        return None
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        try:
            value = float(value)  # numpy scalars
        except (TypeError, ValueError):
            raise ValueError(f"metric {key!r}: not a number: {value!r}") from None
    if isinstance(value, float) and not math.isfinite(value):
        return None
    if isinstance(value, float) and value.is_integer() and key in ("idsw", "frag", "detections", "frames"):
        return int(value)
    return value


def _check_metric(key: str, value: float | int | None) -> None:
    if not KEY_PATTERN.match(key):
        raise ValueError(f"metric {key!r}: not a machine key (lower case, digits, '_'); see metric_key()")
    if value is None:
        return
    if is_fraction(key) and not 0.0 <= value <= 1.0:
        raise ValueError(f"metric {key!r}: {value} is not a fraction in [0, 1] (percent only when printed)")
    if key in ("mota", "moda") and value > 1.0:
        raise ValueError(f"metric {key!r}: {value} is above 1 (a fraction, not percent)")
    if key == "gap" and not -1.0 <= value <= 1.0:
        raise ValueError(f"metric 'gap': {value} is not a fraction in [-1, 1]")


def clean_metrics(metrics: Mapping[str, Any]) -> dict[str, float | int | None]:
    """``metrics`` checked: machine keys, numbers (NaN/inf -> ``None``), fractions in [0, 1]."""
    out: dict[str, float | int | None] = {}
    for key, value in metrics.items():
        number = _number(key, value)
        _check_metric(key, number)
        out[key] = number
    return out


def percent_row_metrics(row: Mapping[str, Any], skip: Iterable[str] = (),
                        rename: Mapping[str, str] | None = None) -> dict[str, float | int | None]:
    """Numeric cells of a printed row under machine keys (``rename[column]`` or :func:`metric_key`), ``(%)`` and
    ``(pp)`` cells divided by 100; text cells and ``skip`` left out."""
    skipped, names = set(skip), dict(rename or {})
    out: dict[str, Any] = {}
    for name, value in row.items():
        if name in skipped or isinstance(value, (str, bool)) or value is None:
            continue
        scale = 0.01 if name.rstrip().endswith(("(%)", "(pp)")) else 1.0
        out[names.get(name) or metric_key(name)] = round(value * scale, 6) if scale != 1.0 else value
    return clean_metrics(out)


def add_printed_rows(doc: Results, table: str, printed: Iterable[Mapping[str, Any]], *,
                     dataset_key: str = "Setup", tracker_key: str = "Tracker",
                     datasets: Mapping[str, str] | None = None, tracker: str = "",
                     rename: Mapping[str, str] | None = None) -> None:
    """Add printed rows to ``doc``: ``dataset`` from column ``dataset_key`` (through ``datasets``), ``tracker`` from
    ``tracker_key`` (else ``tracker``), metrics by :func:`percent_row_metrics`."""
    names = dict(datasets or {})
    for r in printed:
        label = r.get(dataset_key)
        doc.add(table, dataset=None if label is None else names.get(str(label), str(label)),
                tracker=str(r.get(tracker_key, tracker)),
                metrics=percent_row_metrics(r, skip=(dataset_key, tracker_key), rename=rename))


@dataclass
class Results:
    """A results document being built (see the module docstring); rows go into named tables."""

    kind: str
    command: str = ""
    seeds: list[int] = field(default_factory=list)
    sequences: int = 0
    frames: int = 0
    options: dict[str, Any] = field(default_factory=dict)
    notes: dict[str, Any] = field(default_factory=dict)
    tables: dict[str, list[dict[str, Any]]] = field(default_factory=dict)

    def add(self, table: str, *, dataset: str | None, tracker: str, sequence: str | None = None,
            combined: bool = False, metrics: Mapping[str, Any] | None = None,
            info: Mapping[str, Any] | None = None, error: str | None = None) -> dict[str, Any]:
        """Append one row to ``table`` (created on first use) and return it."""
        if not KEY_PATTERN.match(table):
            raise ValueError(f"table {table!r}: not a machine key (lower case, digits, '_')")
        row: dict[str, Any] = {"dataset": dataset, "sequence": sequence, "tracker": str(tracker),
                               "combined": bool(combined), "metrics": clean_metrics(metrics or {})}
        if info:
            row["info"] = {k: _plain(v) for k, v in info.items()}
        if error is not None:
            row["error"] = str(error)
        self.tables.setdefault(table, []).append(row)
        return row

    def to_dict(self) -> dict[str, Any]:
        """The document as plain JSON-able data."""
        header = {
            "lookalike_version": lookalike_version(), "command": self.command or f"lookalike {self.kind}",
            "kind": self.kind, "seeds": [int(s) for s in self.seeds], "sequences": int(self.sequences),
            "frames": int(self.frames),
            "created_utc": _dt.datetime.now(_dt.timezone.utc).replace(microsecond=0).isoformat(),
            "options": {k: _plain(v) for k, v in self.options.items()},
        }
        if self.notes:
            header["notes"] = {k: _plain(v) for k, v in self.notes.items()}
        return {"schema": SCHEMA_ID, "header": header, "tables": self.tables or {"rows": []}}

    def dumps(self) -> str:
        """The document as JSON text."""
        return json.dumps(self.to_dict(), indent=1, allow_nan=False) + "\n"

    def write(self, path: Path) -> Path:
        """Write the document to ``path`` atomically."""
        from lookalike.io.outputs import write_atomic

        return write_atomic(path, self.dumps())


def _plain(value: Any) -> Any:
    if isinstance(value, Path):
        return str(value)
    if isinstance(value, (list, tuple)):
        return [_plain(v) for v in value]
    if isinstance(value, dict):
        return {str(k): _plain(v) for k, v in value.items()}
    if isinstance(value, float) and not math.isfinite(value):
        return None
    if value is None or isinstance(value, (str, int, float, bool)):
        return value
    return str(value)


def schema() -> dict[str, Any]:
    """The JSON Schema of a results document."""
    loaded: dict[str, Any] = json.loads(SCHEMA_PATH.read_text())
    return loaded


def validate(document: Mapping[str, Any]) -> None:
    """Check ``document`` against the schema (``jsonschema.ValidationError``; needs ``jsonschema``)."""
    with needs("jsonschema"):
        import jsonschema  # type: ignore[import-untyped]  # no stubs; test extra

    jsonschema.validate(dict(document), schema())


__all__ = ["FRACTIONS", "SCHEMA_ID", "SCHEMA_PATH", "Results", "add_printed_rows", "clean_metrics", "is_fraction",
           "lookalike_version", "metric_key", "percent_row_metrics", "schema", "validate"]
