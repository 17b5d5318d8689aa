"""Paired comparison of two identifiers on the same sequences: the pooled difference with a 95% percentile bootstrap
interval over sequences (:func:`scipy.stats.bootstrap`, ``paired=True``, fixed seed)."""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from lookalike.io.results import Results

CONFIDENCE = 0.95
RESAMPLES = 9999
SEED = 0  # the bootstrap's random state: the same figures always print the same interval
ONE_SEQUENCE = "one sequence"  # the notes of results without an interval
NEVER = "never"
NO_DETECTIONS = "no detections"
NO_SEQUENCES = "no sequences"


@dataclass(frozen=True)
class PairedDifference:
    """A minus B: ``difference`` and its 95% interval ``[low, high]`` (NaN: none, ``note`` says why)."""

    difference: float
    low: float
    high: float
    n_sequences: int
    note: str = ""

    @property
    def excludes_zero(self) -> bool:
        """Whether the interval lies wholly above or below 0 (False without one)."""
        return bool(self.low > 0 or self.high < 0)


def _interval(data: tuple[np.ndarray, ...], statistic: Any) -> tuple[float, float]:
    from scipy import stats  # (imported here: scipy.stats takes most of a second to import)

    result = stats.bootstrap(data, statistic, paired=True, vectorized=True, method="percentile",
                             confidence_level=CONFIDENCE, n_resamples=RESAMPLES, random_state=SEED)
    ci = result.confidence_interval
    return float(ci.low), float(ci.high)


def _pooled_points(gain: np.ndarray, detections: np.ndarray, axis: int = -1) -> np.ndarray:
    return np.asarray(100.0 * np.sum(gain, axis=axis) / np.sum(detections, axis=axis))


def rate_difference(correct_a: Sequence[float], correct_b: Sequence[float],
                    detections: Sequence[float]) -> PairedDifference:
    """Success rate of A minus B in points, ``100 · sum(correct_A - correct_B) / sum(detections)``, from
    per-sequence counts (sequences without detections left out)."""
    a, b, n = (np.asarray(v, dtype=float) for v in (correct_a, correct_b, detections))
    if not a.shape == b.shape == n.shape or a.ndim != 1:
        raise ValueError(f"per-sequence counts differ in length: {a.shape}, {b.shape}, {n.shape}")
    keep = n > 0
    gain, n = a[keep] - b[keep], n[keep]
    if not n.size:
        return PairedDifference(math.nan, math.nan, math.nan, 0, NO_DETECTIONS)
    point = float(_pooled_points(gain, n))
    if n.size < 2:
        return PairedDifference(point, math.nan, math.nan, int(n.size), ONE_SEQUENCE)
    low, high = _interval((gain, n), _pooled_points)
    return PairedDifference(point, low, high, int(n.size))


def mean_difference(values_a: Sequence[float], values_b: Sequence[float]) -> PairedDifference:
    """Mean per-sequence figure of A minus B (e.g. recovery seconds); with an infinite figure, ``mean(A) -
    mean(B)`` and no interval (``note`` :data:`NEVER`)."""
    a, b = np.asarray(values_a, dtype=float), np.asarray(values_b, dtype=float)
    if a.shape != b.shape or a.ndim != 1:
        raise ValueError(f"per-sequence figures differ in length: {a.shape}, {b.shape}")
    if not a.size:
        return PairedDifference(math.nan, math.nan, math.nan, 0, NO_SEQUENCES)
    n = int(a.size)
    if not (np.isfinite(a).all() and np.isfinite(b).all()):
        with np.errstate(invalid="ignore"):
            point = float(np.mean(a) - np.mean(b))
        return PairedDifference(point, math.nan, math.nan, n, NEVER)
    gain = a - b
    point = float(np.mean(gain))
    if n < 2:
        return PairedDifference(point, math.nan, math.nan, n, ONE_SEQUENCE)
    low, high = _interval((gain,), np.mean)
    return PairedDifference(point, low, high, n)


@dataclass(frozen=True)
class Comparison:
    """``result``: ``tracker`` minus ``baseline`` on data set ``dataset`` (``label``: as printed)."""

    dataset: str
    label: str
    tracker: str
    baseline: str
    result: PairedDifference


def compare_to_first(runs: Mapping[tuple[str, str], Sequence[Any]], datasets: Sequence[str],
                     trackers: Sequence[str], difference: Callable[[Sequence[Any], Sequence[Any]], PairedDifference],
                     label: Callable[[str], str] = str) -> list[Comparison]:
    """Per data set and identifier after the first, ``difference(its per-sequence figures, the first's)`` (``runs``:
    (data set, identifier) -> figures); none where either did not run or the first has < 2 sequences."""
    if len(trackers) < 2:
        return []
    baseline, out = trackers[0], []
    for dataset in datasets:
        base = runs.get((dataset, baseline))
        if base is None or len(base) < 2:
            continue
        for name in dict.fromkeys(trackers[1:]):
            other = runs.get((dataset, name))
            if other is not None and name != baseline:
                out.append(Comparison(dataset, label(dataset), name, baseline, difference(other, base)))
    return out


def interval_text(result: PairedDifference, digits: int = 2) -> str:
    """The interval as printed: ``"-0.41 to +1.20"``, else its note (``"never"``, ``"one sequence"``)."""
    if math.isnan(result.low) or math.isnan(result.high):
        return result.note or "none"
    return f"{result.low:+.{digits}f} to {result.high:+.{digits}f}"


def difference_cells(result: PairedDifference, unit: str, digits: int = 2) -> dict[str, Any]:
    """Printed cells of one comparison: difference, interval, ``Excludes 0`` and ``Sequences``."""
    diff = result.difference
    return {f"Difference ({unit})": "nan" if math.isnan(diff) else f"{diff:+.{digits}f}",
            f"95% CI ({unit})": interval_text(result, digits), "Excludes 0": "yes" if result.excludes_zero else "no",
            "Sequences": result.n_sequences}


def difference_metrics(result: PairedDifference, scale: float = 1.0, suffix: str = "") -> dict[str, float | int]:
    """``difference``, ``ci_low``, ``ci_high`` (times ``scale``, keys + ``suffix``) and ``sequences``."""
    values = {"difference": result.difference, "ci_low": result.low, "ci_high": result.high}
    scaled = {f"{k}{suffix}": v * scale for k, v in values.items()}
    return {**{k: round(v, 6) if math.isfinite(v) else v for k, v in scaled.items()}, "sequences": result.n_sequences}


def difference_title(baseline: str, unit: str, figure: str = "") -> str:
    """The printed title of a table of comparisons with ``baseline`` (``figure``: what is compared)."""
    lead = f"{figure}: difference" if figure else "Difference"
    return f"{lead} from {baseline} ({unit}; {CONFIDENCE:.0%} CI over sequences)"


def comparison_rows(comparisons: Sequence[Comparison], unit: str, digits: int = 2) -> list[dict[str, Any]]:
    """Printed rows of ``comparisons``: ``Setup``, ``Tracker`` and :func:`difference_cells`."""
    return [{"Setup": c.label, "Tracker": c.tracker, **difference_cells(c.result, unit, digits)} for c in comparisons]


def add_comparisons(doc: Results, table: str, comparisons: Sequence[Comparison], figure: str,
                    scale: float = 1.0, suffix: str = "") -> None:
    """Add ``comparisons`` to ``doc`` as table ``table`` (:func:`difference_metrics`), with a note on the method."""
    if not comparisons:
        return
    for c in comparisons:
        info = {"baseline": c.baseline, "figure": figure, **({"note": c.result.note} if c.result.note else {})}
        doc.add(table, dataset=c.dataset, tracker=c.tracker, metrics=difference_metrics(c.result, scale, suffix),
                info=info)
    doc.notes[table] = (f"{figure} of the row's identifier minus the baseline's on the same sequences; "
                        f"{CONFIDENCE:.0%} percentile bootstrap interval over sequences (paired, {RESAMPLES} "
                        f"resamples, random state {SEED}); null interval: see the row's note")


__all__ = ["CONFIDENCE", "NEVER", "NO_DETECTIONS", "NO_SEQUENCES", "ONE_SEQUENCE", "RESAMPLES", "SEED", "Comparison",
           "PairedDifference", "add_comparisons", "comparison_rows", "difference_cells", "difference_metrics",
           "difference_title", "interval_text", "mean_difference", "rate_difference"]
