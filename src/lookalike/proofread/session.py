"""A proofreading session over one tracking result: doubtful ranges, corrections, undo, export and replay.

With a known number of identities ``n_targets`` each correction becomes a constraint on the offline closed set
(:func:`lookalike.trackers.offline.closed_set.assign_identities`) and the whole assignment is solved again, so later
frames that depended on the corrected link change too; without it corrections are plain edits
(:func:`lookalike.proofread.edits.apply_edit`). The latest correction wins: earlier ones that conflict with it are
dropped (newest kept first). Rows are MOTChallenge ``(k, 10)``, frames 1-based."""

from __future__ import annotations

import json
import os
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import numpy as np

from lookalike.io.det_format import read_detections
from lookalike.io.motchallenge import read_mot, write_mot
from lookalike.io.outputs import write_atomic
from lookalike.proofread.edits import Change, Correction, apply_edit, changes, check, colocated
from lookalike.trackers.offline.closed_set import ClosedSetConfig, assign_identities, closed_set_input
from lookalike.trackers.offline.confidence import DOUBTFUL_BELOW, assignment_confidence, doubtful_ranges
from lookalike.trackers.offline.constraints import ChainConstraints, Row
from lookalike.types.mot_table import MotTable

__all__ = ["Doubt", "Session"]


@dataclass(frozen=True)
class Doubt:
    """A doubtful range: id ``track`` in frames ``first``-``last`` (inclusive); ``doubt`` is the sum over its rows of
    how far their confidence falls below the threshold (larger: more doubtful)."""

    track: int
    first: int
    last: int
    doubt: float


def _rows_of(table_or_rows: np.ndarray | MotTable | str | os.PathLike[str]) -> np.ndarray:
    if isinstance(table_or_rows, (str, os.PathLike, MotTable)):
        t = table_or_rows if isinstance(table_or_rows, MotTable) else read_mot(table_or_rows)
        rows = np.column_stack([t.frame, t.track_id, t.xywh, t.conf, np.full((len(t), 3), -1.0)])
    else:
        rows = np.asarray(table_or_rows, dtype=float)
        if rows.ndim != 2 or (len(rows) and rows.shape[1] < 6):
            raise ValueError(f"rows: expected MOTChallenge rows (k, >= 6), got shape {rows.shape}")
        if rows.shape[1] < 10:
            rows = np.hstack([rows, np.full((len(rows), 10 - rows.shape[1]), -1.0)])
    rows = rows[:, :10].reshape(-1, 10)
    out: np.ndarray = rows[np.lexsort((rows[:, 1], rows[:, 0]))]
    return out


class Session:
    """Proofreading of ``tracks`` (rows or a MOTChallenge file). With ``n_targets`` corrections re-solve the closed set
    over the tracklets of ``solver_input`` (the rows the closed set was solved from), else of ``detections`` (rows, a
    table, or a file in any layout ``lookalike track`` reads; their online pass, as ``--offline`` makes it), else of
    the tracks themselves. ``frame_rate`` in frames/s (confidence windows and the solver's motion). ``shapes``: blob
    shape vectors ``(k, SHAPE_SIZE)`` of the detections, which column 9 of ``solver_input`` indexes (``detections``:
    one per row); with them each re-solve weighs the look learned from the video, as ``track --targets N`` on a blob
    video does; ``parts``: the blobs' parts vectors (one per shape vector), on which the animals of a merged blob are
    placed.

    Attributes:
        rows: the current rows ``(k, 10)``, sorted by frame, then id.
        initial: the rows as loaded.
        corrections: every correction applied and not undone, in order (dropped ones too: :attr:`dropped`).
        last_change: what the last ``apply`` or ``undo`` changed."""

    def __init__(self, tracks: np.ndarray | str | os.PathLike[str], *, frame_rate: float = 30.0,
                 n_targets: int | None = None,
                 detections: np.ndarray | MotTable | str | os.PathLike[str] | None = None,
                 solver_input: np.ndarray | None = None, config: ClosedSetConfig | None = None,
                 shapes: np.ndarray | None = None, parts: np.ndarray | None = None) -> None:
        if not frame_rate > 0:
            raise ValueError(f"frame_rate must be > 0 frames/s, got {frame_rate}")
        if n_targets is not None and int(n_targets) < 1:
            raise ValueError(f"n_targets must be >= 1, got {n_targets}")
        self.frame_rate = float(frame_rate)
        self.n_targets = None if n_targets is None else int(n_targets)
        self.config = config or ClosedSetConfig()
        self.initial = _rows_of(tracks)
        if not len(self.initial):
            raise ValueError("tracks: no rows")
        self._solver_rows: np.ndarray | None = None
        if self.n_targets is not None:
            if solver_input is not None:
                self._solver_rows = _rows_of(solver_input)
            elif detections is not None:
                det = _rows_of(read_detections(detections)[0] if isinstance(detections, (str, os.PathLike))
                               else detections)
                if not len(det):
                    raise ValueError("detections: no rows")
                self._solver_rows = closed_set_input(det, self.frame_rate, int(det[:, 0].max()),
                                                     index=shapes is not None)
            else:
                self._solver_rows = self.initial.copy()
        if shapes is not None:
            index = None if self._solver_rows is None or solver_input is None and detections is None else \
                self._solver_rows[:, 9]
            if index is None or (len(index) and not (0 <= index.min() and index.max() < len(shapes))):
                raise ValueError("shapes: need n_targets and detections or solver_input whose column 9 indexes "
                                 f"them ({len(shapes)} shapes)")
            if parts is not None and len(parts) != len(shapes):
                raise ValueError(f"parts: expected one per shape vector ({len(shapes)}), got {len(parts)}")
        self._shapes, self._blob_parts = shapes, parts if shapes is not None else None
        self.rows = self.initial.copy()
        self.corrections: list[Correction] = []
        self._parts: list[ChainConstraints | None] = []  # per correction its constraints; None: dropped
        self._history: list[tuple[np.ndarray, list[ChainConstraints | None]]] = []
        self.last_change = Change((), (), 0)

    @property
    def propagates(self) -> bool:
        """Whether corrections re-solve the closed set (a known ``n_targets``)."""
        return self._solver_rows is not None

    def confidence(self) -> np.ndarray:
        """``(k,)`` probability that each current row's identity is right, in the order of :attr:`rows`."""
        return assignment_confidence(self.rows, self.frame_rate)

    def doubtful(self, threshold: float = DOUBTFUL_BELOW) -> list[Doubt]:
        """The doubtful ranges of the current rows (rows with confidence below ``threshold``, merged within one
        second), most doubtful first."""
        conf = self.confidence()
        out = []
        for track, spans in doubtful_ranges(self.rows, conf, self.frame_rate, threshold).items():
            sel = self.rows[:, 1] == track
            for a, b in spans:
                inside = sel & (self.rows[:, 0] >= a) & (self.rows[:, 0] <= b)
                out.append(Doubt(track, a, b, float(np.clip(threshold - conf[inside], 0, None).sum())))
        out.sort(key=lambda d: (-d.doubt, d.first, d.track))
        return out

    @property
    def dropped(self) -> list[bool]:
        """Per correction in :attr:`corrections`, whether a later one that conflicted with it dropped it."""
        return [p is None for p in self._parts]

    def apply(self, correction: Correction) -> Change:
        """Apply ``correction``; returns what changed, also kept as :attr:`last_change`. With ``n_targets``, earlier
        corrections that conflict with it are dropped (listed in the change's ``dropped``; newest kept first).
        ValueError, and nothing changed, when it names an unknown id or frame or cannot hold even alone."""
        check(self.rows, correction)
        parts = list(self._parts)
        dropped: tuple[Correction, ...] = ()
        if self._solver_rows is None:
            new, part = apply_edit(self.rows, correction), ChainConstraints()
        else:
            part = self._constrain(correction)
            new, parts = self._solve_latest_wins(parts, part)
            dropped = tuple(c for c, was, now in zip(self.corrections, self._parts, parts)
                            if was is not None and now is None)
        self._history.append((self.rows, self._parts))
        self.corrections.append(correction)
        self.last_change = replace(changes(self.rows, new), dropped=dropped)
        self.rows, self._parts = new, [*parts, part]
        return self.last_change

    def _solve_latest_wins(self, parts: list[ChainConstraints | None],
                           part: ChainConstraints) -> tuple[np.ndarray, list[ChainConstraints | None]]:
        """The closed set under ``part`` and the earlier ``parts``; when they conflict, ``part`` with as many earlier
        ones as hold, tried newest first (the others become None)."""
        try:
            return self._solve(_joined([*parts, part])), parts
        except ValueError:
            pass
        new = self._solve(part)  # ValueError: the correction cannot hold even alone
        kept: list[ChainConstraints | None] = [None] * len(parts)
        for i in reversed(range(len(parts))):
            if parts[i] is None:
                continue
            trial = [*kept[:i], parts[i], *kept[i + 1:]]
            try:
                new, kept = self._solve(_joined([*trial, part])), trial
            except ValueError:
                pass
        return new, kept

    def undo(self) -> Change:
        """Take back the last correction (and bring back the ones it dropped); ValueError when there is none."""
        if not self.corrections:
            raise ValueError("undo: no correction to take back")
        rows, self._parts = self._history.pop()
        self.corrections.pop()
        self.last_change = changes(self.rows, rows)
        self.rows = rows
        return self.last_change

    # -- the closed set -------------------------------------------------------------------------------------------

    def _anchor(self, track: int, frame: int, after: bool) -> Row | None:
        """The solver's input row under ``track``'s first row at or after ``frame`` (``after``) or its last row
        before it, as ``(frame, input id)``; None when there is none. Rows pair one-to-one per frame, so two ids that
        pass close by never share one input row."""
        assert self._solver_rows is not None
        mine = self.rows[self.rows[:, 1] == track, 0]
        mine = mine[mine >= frame] if after else mine[mine < frame][::-1]
        for lo in range(0, len(mine), 32):  # outwards from the frame, 32 frames at a time
            frames = mine[lo:lo + 32]
            here = self.rows[np.isin(self.rows[:, 0], frames)]
            near = self._solver_rows[np.isin(self._solver_rows[:, 0], frames)]
            ia, ib = colocated(here, near)
            ours = here[ia, 1] == track
            if ours.any():
                f = here[ia[ours], 0]
                best = int(np.argmin(f) if after else np.argmax(f))
                return int(near[ib[ours][best], 0]), int(near[ib[ours][best], 1])
        return None

    def _runs(self, track: int) -> list[Row]:
        """One solver input row per run of one input id under ``track`` (its first)."""
        assert self._solver_rows is not None
        ia, ib = colocated(self.rows, self._solver_rows)
        ours = self.rows[ia, 1] == track
        src = self._solver_rows[ib[ours]]
        src = src[np.argsort(src[:, 0], kind="stable")]
        first = np.r_[True, src[1:, 1] != src[:-1, 1]] if len(src) else np.zeros(0, bool)
        return [(int(f), int(s)) for f, s in src[first, :2]]

    def _constrain(self, c: Correction) -> ChainConstraints:
        """The constraints of ``c`` on the current rows: its rows cut and fixed (module doc of
        :mod:`lookalike.proofread`)."""
        cut: list[Row] = []
        ident: list[tuple[Row, int]] = []
        apart: list[tuple[Row, Row]] = []
        clutter: list[Row] = []
        if c.kind in ("swap", "assign", "split"):
            assert c.frame is not None
            a_after, a_before = self._anchor(c.track, c.frame, True), self._anchor(c.track, c.frame, False)
            if a_after is None:
                raise ValueError(f"correction {c.kind}: no row of track {c.track} from frame {c.frame} on to correct")
            cut.append(a_after)
            if c.kind == "split":
                if a_before is None:
                    raise ValueError(f"correction split: track {c.track} has no rows before frame {c.frame}")
                apart.append((a_before, a_after))
            else:
                assert c.other is not None
                ident.append((a_after, c.other))
                if a_before is not None:
                    ident.append((a_before, c.track))
                if c.other in self.rows[:, 1]:
                    b_before = self._anchor(c.other, c.frame, False)
                    if b_before is not None:
                        ident.append((b_before, c.other))
                    b_after = self._anchor(c.other, c.frame, True)
                    if c.kind == "swap" and b_after is not None:
                        cut.append(b_after)
                        ident.append((b_after, c.track))
        elif c.kind == "merge":
            assert c.other is not None
            ident += [(r, c.track) for r in self._runs(c.track) + self._runs(c.other)]
        else:
            clutter += self._runs(c.track)
        return ChainConstraints(tuple(cut), tuple(ident), tuple(apart), tuple(clutter))

    def _solve(self, cons: ChainConstraints) -> np.ndarray:
        """The closed set under ``cons``, its free identities renamed to the current ids they overlap most."""
        assert self._solver_rows is not None and self.n_targets is not None
        new = assign_identities(self._solver_rows, self.n_targets, self.frame_rate, self.config, cons, self._shapes,
                                 self._blob_parts)
        fixed = {j for _, j in cons.identity}
        free_new = sorted(set(np.unique(new[:, 1]).astype(int).tolist()) - fixed)
        free_old = sorted(set(np.unique(self.rows[:, 1]).astype(int).tolist()) - fixed)
        if free_new and free_old:
            from lookalike._lsap import linear_sum_assignment

            ia, ib = colocated(self.rows, new)
            overlap = np.zeros((len(free_old), len(free_new)))
            io, inew = {t: k for k, t in enumerate(free_old)}, {t: k for k, t in enumerate(free_new)}
            for a, b in zip(self.rows[ia, 1].astype(int).tolist(), new[ib, 1].astype(int).tolist()):
                if a in io and b in inew:
                    overlap[io[a], inew[b]] += 1
            r, col = linear_sum_assignment(-overlap)
            rename = {free_new[k]: free_old[q] for q, k in zip(r, col)}
            spare = iter(sorted(set(range(1, self.n_targets + 1)) - fixed - set(rename.values())))
            rename.update({t: next(spare) for t in free_new if t not in rename})
            new[:, 1] = [rename.get(int(i), int(i)) for i in new[:, 1]]
        out: np.ndarray = new[np.lexsort((new[:, 1], new[:, 0]))]
        return out

    # -- export and replay ----------------------------------------------------------------------------------------

    def save(self, tracks: str | os.PathLike[str], log: str | os.PathLike[str] | None = None) -> None:
        """Write the current rows as a MOTChallenge file and (``log``) the corrections as JSON lines."""
        write_mot(tracks, self.rows)
        if log is not None:
            write_atomic(log, self.log_text())

    def log_text(self) -> str:
        """The corrections log: a header line (mode) and one JSON line per correction, in order."""
        head = json.dumps({"lookalike_proofread": 1, "n_targets": self.n_targets, "frame_rate": self.frame_rate})
        return "".join(line + "\n" for line in [head, *(c.to_json() for c in self.corrections)])

    def replay(self, log: str | os.PathLike[str] | list[Correction]) -> Change:
        """Apply the corrections of a log (a path, or corrections) in order; the session must hold the same input the
        log was made on, with its ``n_targets`` (ValueError otherwise, on a line that is no correction, and on a
        correction that does not apply)."""
        if isinstance(log, list):
            todo = log
        else:
            logged = log_header(log)
            if logged is not None and logged.get("n_targets") != self.n_targets:
                raise ValueError(f"{log}: made with n_targets={logged.get('n_targets')}, but this session has "
                                 f"n_targets={self.n_targets}")
            todo = []
            for number, line in enumerate(Path(log).read_text(encoding="utf-8").splitlines(), 1):
                if line.strip() and "lookalike_proofread" not in line:
                    try:
                        todo.append(Correction.from_json(line))
                    except ValueError as exc:
                        raise ValueError(f"{log}:{number}: {exc} (a line cut short? remove it to go on)") from None
        before = self.rows
        for k, c in enumerate(todo):
            try:
                self.apply(c)
            except ValueError as exc:
                where = "replay" if isinstance(log, list) else str(log)
                raise ValueError(f"{where}: correction {k + 1} ({c.to_json()}): {exc}") from exc
        return changes(before, self.rows)


def log_header(log: str | os.PathLike[str]) -> dict[str, Any] | None:
    """The header of a corrections log (``n_targets``, ``frame_rate``), or None when its first line is none."""
    with open(log, encoding="utf-8") as fh:
        first = fh.readline()
    try:
        head = json.loads(first)
    except ValueError:
        return None
    return head if isinstance(head, dict) and "lookalike_proofread" in head else None


def _joined(parts: list[ChainConstraints | None]) -> ChainConstraints:
    """The constraints of every part that is not None, in order."""
    kept = [p for p in parts if p is not None]
    return ChainConstraints(*(sum((getattr(p, f) for p in kept), ()) for f in ("cut", "identity", "apart", "clutter")))
