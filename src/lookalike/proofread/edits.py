"""Corrections of a tracking result and their plain edits on MOTChallenge rows ``(k, 10)`` (1-based frame, id, ``x, y,
w, h`` px, ...): what a proofreader does when no closed set re-solves them."""

from __future__ import annotations

import json
from dataclasses import asdict, dataclass

import numpy as np

__all__ = ["KINDS", "Change", "Correction", "apply_edit", "changes", "colocated"]

KINDS = ("swap", "merge", "split", "delete", "assign")


@dataclass(frozen=True)
class Correction:
    """One correction. ``swap``: ``track`` and ``other`` exchange ids from ``frame`` on; ``merge``: ``other``'s rows
    join ``track``; ``split``: ``track``'s rows from ``frame`` on get a new id; ``delete``: ``track`` is false, its
    rows go; ``assign``: ``track``'s rows from ``frame`` on are identity ``other``. Frames 1-based."""

    kind: str
    track: int
    other: int | None = None
    frame: int | None = None

    def __post_init__(self) -> None:
        if self.kind not in KINDS:
            raise ValueError(f"correction: unknown kind {self.kind!r} (one of {', '.join(KINDS)})")
        needs_other = self.kind in ("swap", "merge", "assign")
        needs_frame = self.kind in ("swap", "split", "assign")
        if needs_other != (self.other is not None) or needs_frame != (self.frame is not None):
            raise ValueError(f"correction {self.kind}: needs track{', other' * needs_other}{', frame' * needs_frame}"
                             f" and nothing else, got {self}")
        if self.other is not None and self.other == self.track:
            raise ValueError(f"correction {self.kind}: track and other are both {self.track}")

    def to_json(self) -> str:
        """One JSON line (no newline)."""
        return json.dumps({k: v for k, v in asdict(self).items() if v is not None}, sort_keys=True)

    @classmethod
    def from_json(cls, line: str) -> Correction:
        """The correction of one JSON line (as :meth:`to_json` writes it; ids and frame integers); ValueError when
        it is not one."""
        data = json.loads(line)
        if not isinstance(data, dict) or set(data) - {"kind", "track", "other", "frame"}:
            raise ValueError(f"correction: expected an object with kind, track[, other, frame], got {line[:80]!r}")
        if not isinstance(data.get("kind"), str) or data.get("track") is None:
            raise ValueError(f"correction: kind (text) and track are required, got {line[:80]!r}")
        given = {k: v for k, v in data.items() if k != "kind" and v is not None}
        if any(type(v) is not int for v in given.values()):
            raise ValueError(f"correction: track, other and frame must be whole numbers, got {line[:80]!r}")
        return cls(data["kind"], data["track"], given.get("other"), given.get("frame"))


@dataclass(frozen=True)
class Change:
    """What a correction changed: the frames (sorted, 1-based) and ids (sorted) whose rows moved, appeared or went,
    how many rows, how many of the old rows are ``removed`` (no row left where they were: a deletion, or a closed set
    with no identity free for them), and the earlier corrections it ``dropped`` because they conflicted with it."""

    frames: tuple[int, ...]
    ids: tuple[int, ...]
    rows: int
    dropped: tuple[Correction, ...] = ()
    removed: int = 0

    def describe(self, max_spans: int = 6) -> str:
        """One line: ``changed 120 rows, ids 3, 7, frames 200-260, 400-410``, then the dropped corrections."""
        drop = "".join(f"; dropped the earlier conflicting correction {c.to_json()}" for c in self.dropped)
        if not self.rows:
            return "changed nothing" + drop
        f = np.asarray(self.frames)
        starts = np.flatnonzero(np.r_[True, np.diff(f) > 1])
        ends = np.r_[starts[1:] - 1, len(f) - 1]
        spans = [f"{f[a]}-{f[b]}" if f[b] > f[a] else f"{f[a]}" for a, b in zip(starts, ends)]
        more = f" (+{len(spans) - max_spans} more)" if len(spans) > max_spans else ""
        gone = f" ({self.removed} of them removed)" if self.removed else ""
        return (f"changed {self.rows} rows{gone}, ids {', '.join(map(str, self.ids))}, frames "
                f"{', '.join(spans[:max_spans])}{more}{drop}")


def _check_track(rows: np.ndarray, track: int, name: str = "track") -> np.ndarray:
    mask: np.ndarray = rows[:, 1] == track
    if not mask.any():
        raise ValueError(f"correction: unknown {name} id {track}")
    return mask


def _check_frame(rows: np.ndarray, frame: int, mask: np.ndarray, track: int) -> None:
    lo, hi = int(rows[:, 0].min()), int(rows[:, 0].max())
    if not lo <= frame <= hi:
        raise ValueError(f"correction: frame {frame} is out of range {lo}-{hi}")
    if not (rows[mask, 0] >= frame).any():
        raise ValueError(f"correction: track {track} has no rows at or after frame {frame}")


def check(rows: np.ndarray, c: Correction) -> None:
    """ValueError when ``c`` names an id not in ``rows`` or a frame outside them."""
    mask = _check_track(rows, c.track)
    if c.other is not None and c.kind != "assign":
        _check_track(rows, c.other, "other")
    if c.kind == "assign" and c.other is not None and c.other < 1:
        raise ValueError(f"correction assign: identity must be >= 1, got {c.other}")
    if c.frame is not None:
        _check_frame(rows, c.frame, mask, c.track)


def apply_edit(rows: np.ndarray, c: Correction) -> np.ndarray:
    """``rows`` after ``c`` as a plain edit (a new array; rows sorted by frame, then id)."""
    rows = np.array(rows, dtype=float)
    check(rows, c)
    t = rows[:, 1] == c.track
    if c.kind == "swap":
        later = rows[:, 0] >= c.frame
        o = rows[:, 1] == c.other
        rows[t & later, 1], rows[o & later, 1] = c.other, c.track
    elif c.kind == "merge":
        o = rows[:, 1] == c.other
        clash = np.intersect1d(rows[t, 0], rows[o, 0])
        if len(clash):
            raise ValueError(f"correction merge: tracks {c.track} and {c.other} both have rows in frame "
                             f"{int(clash[0])}")
        rows[o, 1] = c.track
    elif c.kind == "split":
        rows[t & (rows[:, 0] >= c.frame), 1] = rows[:, 1].max() + 1
    elif c.kind == "delete":
        rows = rows[~t]
    else:
        moved = t & (rows[:, 0] >= c.frame)
        clash = np.intersect1d(rows[moved, 0], rows[rows[:, 1] == c.other, 0])
        if len(clash):
            raise ValueError(f"correction assign: identity {c.other} already has a row in frame {int(clash[0])} "
                             f"(swap the two instead)")
        rows[moved, 1] = c.other
    out: np.ndarray = rows[np.lexsort((rows[:, 1], rows[:, 0]))]
    return out


def colocated(a: np.ndarray, b: np.ndarray, within: float = 0.5) -> tuple[np.ndarray, np.ndarray]:
    """Indices ``(ia, ib)`` of rows of ``a`` and ``b`` in the same frame whose box centres are less than ``within``
    box sizes √(w·h) apart, each row paired at most once (nearest first)."""
    ia_all: list[np.ndarray] = []
    ib_all: list[np.ndarray] = []
    if not len(a) or not len(b):
        return np.zeros(0, int), np.zeros(0, int)
    oa, ob = np.argsort(a[:, 0], kind="stable"), np.argsort(b[:, 0], kind="stable")
    fa, fb = a[oa, 0], b[ob, 0]
    ca, cb = a[:, 2:4] + a[:, 4:6] / 2, b[:, 2:4] + b[:, 4:6] / 2
    size = np.sqrt(np.maximum(a[:, 4] * a[:, 5], 1.0))
    for f in np.intersect1d(fa, fb):
        ra = oa[np.searchsorted(fa, f):np.searchsorted(fa, f, "right")]
        rb = ob[np.searchsorted(fb, f):np.searchsorted(fb, f, "right")]
        d = np.linalg.norm(ca[ra][:, None] - cb[rb][None], axis=2) / size[ra][:, None]
        pa, pb = np.nonzero(d < within)
        if not len(pa):
            continue
        order = np.argsort(d[pa, pb], kind="stable")
        used_a: set[int] = set()
        used_b: set[int] = set()
        for x, y in zip(pa[order].tolist(), pb[order].tolist()):
            if x not in used_a and y not in used_b:
                used_a.add(x)
                used_b.add(y)
                ia_all.append(ra[x:x + 1])
                ib_all.append(rb[y:y + 1])
    if not ia_all:
        return np.zeros(0, int), np.zeros(0, int)
    return np.concatenate(ia_all), np.concatenate(ib_all)


def changes(old: np.ndarray, new: np.ndarray) -> Change:
    """The rows of ``old`` and ``new`` that differ: a row with no co-located row of the same id in the other."""
    ia, ib = colocated(old, new)
    same = old[ia, 1] == new[ib, 1]
    kept_a = np.zeros(len(old), bool)
    kept_b = np.zeros(len(new), bool)
    kept_a[ia[same]], kept_b[ib[same]] = True, True
    diff = np.vstack([old[~kept_a, :2], new[~kept_b, :2]])
    return Change(tuple(np.unique(diff[:, 0]).astype(int).tolist()), tuple(np.unique(diff[:, 1]).astype(int).tolist()),
                  int(len(diff)), removed=len(old) - len(ia))
