"""Matplotlib figures written as PNG: bird's-eye paths and grouped bar charts (Agg backend, lazy import)."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from lookalike._optional import needs
from lookalike.io.outputs import atomic_path
from lookalike.viz.colors import identity_colour, rgb_hex


def _pyplot() -> Any:
    with needs("matplotlib"):
        import matplotlib

    matplotlib.use("Agg")
    with needs("matplotlib"):
        import matplotlib.pyplot as plt

    return plt


def birdseye_plot(path: Path | str, truth: np.ndarray, estimated: np.ndarray, *,
                  field_m: tuple[float, float] | None = None, observer: np.ndarray | tuple[float, float] | None = None,
                  title: str = "") -> Path:
    """True (solid) and estimated (dots) paths of each agent seen from above.

    Args:
        truth: ``(T, N, 2)`` true positions (m); NaN where not to draw.
        estimated: ``(T, N, 2)`` estimated positions (m) of each agent; NaN where none.
        field_m: ``(length, width)`` of a field centred at the origin to outline, or None.
        observer: ``(2,)`` position of the observer to mark, or None."""
    t, e = np.asarray(truth, dtype=float), np.asarray(estimated, dtype=float)
    if t.ndim != 3 or t.shape[2] != 2 or e.shape != t.shape:
        raise ValueError(f"truth/estimated: need equal (T, N, 2) shapes, got {t.shape} and {e.shape}")
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(7, 5))
    if field_m is not None:
        lx, ly = field_m[0] / 2, field_m[1] / 2
        ax.plot([-lx, lx, lx, -lx, -lx], [-ly, -ly, ly, ly, -ly], color="#6a9", lw=1)
        ax.plot([0, 0], [-ly, ly], color="#6a9", lw=0.8)
    for j in range(t.shape[1]):
        c = rgb_hex(identity_colour(j))
        ax.plot(t[:, j, 0], t[:, j, 1], color=c, lw=2, label=f"robot {j + 1} true")
        ax.plot(e[:, j, 0], e[:, j, 1], ".", color=c, ms=2.5, alpha=0.6, label=f"robot {j + 1} estimated")
    if observer is not None:
        ax.plot(*np.asarray(observer, dtype=float)[:2], "k^", ms=9, label="observer")
    ax.set_aspect("equal")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    if title:
        ax.set_title(title, fontsize=10)
    ax.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.01, 1.0))
    fig.tight_layout()
    return _save(fig, plt, path)


def grouped_bar_chart(path: Path | str, rows: Sequence[Mapping[str, Any]], group: str, series: str, value: str,
                      *, ylabel: str | None = None, ylim: tuple[float, float] | None = (0, 100),
                      title: str = "") -> Path:
    """Bars of ``row[value]`` per ``row[group]`` (x axis), one colour per ``row[series]``."""
    if not rows:
        raise ValueError("rows: nothing to plot")
    for key in (group, series, value):
        if key not in rows[0]:
            raise ValueError(f"rows: no column {key!r}; columns: {', '.join(rows[0])}")
    groups = list(dict.fromkeys(str(r[group]) for r in rows))
    names = list(dict.fromkeys(str(r[series]) for r in rows))
    table = {(str(r[group]), str(r[series])): float(r[value]) for r in rows}
    plt = _pyplot()
    x = np.arange(len(groups))
    width = 0.8 / len(names)
    fig, ax = plt.subplots(figsize=(max(6.0, 1.1 * len(groups) + 2), 4))
    for i, name in enumerate(names):
        heights = [table.get((g, name), np.nan) for g in groups]
        ax.bar(x + (i - (len(names) - 1) / 2) * width, heights, width, label=name,
               color=rgb_hex(identity_colour(i)))
    ax.set_xticks(x, groups, rotation=25 if len(groups) > 3 else 0, ha="right" if len(groups) > 3 else "center",
                  fontsize=8)
    ax.set_ylabel(ylabel or value)
    if ylim is not None:
        ax.set_ylim(*ylim)
    if title:
        ax.set_title(title, fontsize=10)
    ax.grid(axis="y", alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    return _save(fig, plt, path)


def _save(fig: Any, plt: Any, path: Path | str) -> Path:
    """Save ``fig`` to ``path`` (in the format its suffix names, PNG without one) through
    :func:`~lookalike.io.outputs.atomic_path`: an interrupted save leaves the earlier file whole."""
    out = Path(path)
    with atomic_path(out) as tmp:
        fig.savefig(tmp, dpi=100, format=out.suffix[1:].lower() or "png")
    plt.close(fig)
    return out
