"""Anonymous points per frame as tracker input (point CSV or MOTChallenge rows, 1-based frames; ``ValueError`` naming
file and line), and points as small square boxes for the box trackers and back."""

from __future__ import annotations

import math
import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from lookalike.io.motchallenge import MAX_ID
from lookalike.io.rules import DECOMPRESS_ERRORS, frame_problems, not_a_file, open_text, read_text, without_comment
from lookalike.types._validate import first_fraction
from lookalike.types.mot_table import detection_rows

__all__ = ["COLUMN_NAMES", "POINT_VEL_NOISE", "PointFrames", "points_to_rows", "read_id_points", "read_points_csv",
           "read_points_mot", "rows_to_points", "typical_spacing", "typical_step"]

# boxtrack's velocity noise (box sides per frame) for points as boxes, chosen on the simulated arenas of
# benchmarks/closed_points.py, seeds 0-29 (docs/closed-set.md).
POINT_VEL_NOISE = 0.02


@dataclass(frozen=True, eq=False)
class PointFrames:
    """Anonymous points of a sequence: per frame (index = frame − 1) ``(n, 2)`` positions; ``path``: the file;
    ``zero_based``: its frames started at 0 (file frame 0 is frame 1)."""

    points: list[np.ndarray]
    path: Path | None = None
    zero_based: bool = False

    def __len__(self) -> int:
        return len(self.points)

    @property
    def count(self) -> int:
        """Number of points over all frames."""
        return int(sum(len(p) for p in self.points))


MAX_COORDINATE = 1e9  # pixels: a point or box value beyond this (in absolute value) is an error naming its line

# The header names each column of a points file is recognised by (case and quotes ignored); an unnamed column, as
# pandas' index column, and any other name are columns skipped.
COLUMN_NAMES: dict[str, tuple[str, ...]] = {
    "frame": ("frame", "t", "frame_id", "frameid", "frame_no"),
    "id": ("id", "track_id", "trackid", "object_id", "obj_id", "hexbug"),
    "x": ("x",),
    "y": ("y",),
}

_BOX_NAMES = {"w", "h", "width", "height", "bb_width", "bb_height"}  # a header naming one names boxes, not points


def _header(path: Path) -> tuple[int, list[str]] | None:
    """``(line number, lower-case names)`` of the header line of ``path`` (a first data line whose first field is no
    number), else None."""
    if not path.is_file():
        return None
    try:
        with open_text(path, errors="replace") as fh:
            lines = ((no, without_comment(line).strip()) for no, line in enumerate(fh, start=1))
            first = next(((no, text) for no, text in lines if text), None)
    except DECOMPRESS_ERRORS:
        return None  # (reading the file again names the problem)
    if first is None:
        return None
    no, fields = first[0], [f.strip() for f in first[1].split(",")]
    try:
        float(fields[0])
        return None
    except ValueError:
        return no, [f.strip("\"'").lower() for f in fields]


def _columns(path: Path, default: dict[str, int]) -> dict[str, int]:
    """The column of each role in ``default`` (frame, id, x, y): the one a header names (:data:`COLUMN_NAMES`), else
    the default one, unless the header leaves that unnamed or names it for another role (a ``ValueError`` naming the
    header)."""
    header = _header(path)
    if header is None:
        return default
    no, names = header
    named = {role: names.index(n) for role, aliases in COLUMN_NAMES.items()
             for n in reversed(aliases) if n in names}
    out = {}
    for role, k in default.items():
        if role in named:
            out[role] = named[role]
        elif k >= len(names) or (names[k] and names[k] not in {a for v in COLUMN_NAMES.values() for a in v}):
            out[role] = k  # (a column past the header's names, or named otherwise: taken by its place)
        else:
            raise ValueError(f"{path}:{no}: the header names no {role} column (one of "
                             f"{', '.join(COLUMN_NAMES[role])}) in {','.join(names)[:80]!r}")
    return out


def _parse(path: Path, picks: list[int], pixels: int,
           extra: tuple[int, ...] = ()) -> tuple[list[tuple[int, list[float]]], bool]:
    """``(line number, values)`` of the data lines (blank lines and one leading header skipped), and whether the file
    is 0-based: the values of columns ``picks`` (the first one the frame, 1-based; a file whose first frame is 0 is
    read as 0-based and shifted by 1), then of the columns ``extra`` a line has; values from the ``pixels``-th on are
    pixels, at most :data:`MAX_COORDINATE` in absolute value."""
    if path.is_dir():
        raise ValueError(f"{path}: is a folder; expected a points file (frame,x,y CSV or MOTChallenge rows)")
    if not path.is_file():
        raise FileNotFoundError(f"{path}: no such file")
    columns = max(picks) + 1
    out = []
    first = True
    base: int | None = None  # the first frame's number: 0 for a 0-based file, else 1
    for no, line in enumerate(read_text(path).splitlines(), start=1):
        text = without_comment(line).strip()
        if not text:
            continue
        fields = [f.strip() for f in text.split(",")]
        if first:
            first = False
            try:
                float(fields[0])
            except ValueError:
                continue  # a header
        if len(fields) < columns:
            raise ValueError(f"{path}:{no}: expected at least {columns} comma-separated columns, got "
                             f"{len(fields)}: {text!r}")
        try:
            values = [float(fields[k]) for k in (*picks, *(k for k in extra if k < len(fields)))]
        except ValueError:
            raise ValueError(f"{path}:{no}: not a number in {text!r}") from None
        if not all(math.isfinite(v) for v in values):
            raise ValueError(f"{path}:{no}: NaN or infinity in {text!r}")
        if any(abs(v) > MAX_COORDINATE for v in values[pixels:]):
            raise ValueError(f"{path}:{no}: a coordinate beyond {MAX_COORDINATE:g} px in {text[:80]!r}")
        frame = values[0]
        if base is None:
            base = 0 if frame == 0 else 1
        if frame < base or frame != int(frame):
            why = (" (0-based frames: the first line is frame 0)" if base == 0 else
                   " (a file is read as 0-based only when its first line is frame 0)" if frame == 0 else "")
            raise ValueError(f"{path}:{no}: frame must be an integer >= {base}, got {fields[picks[0]]!r}{why}")
        values[0] = frame + 1 - base
        out.append((no, values))
    problem = frame_problems(np.array([v[0] for _, v in out]))  # a stray huge frame number
    if problem is not None:
        raise ValueError(f"{path}:{out[problem[0]][0]}: invalid frame: {problem[1]}")
    return out, base == 0


def _group(path: Path, frames: np.ndarray, xy: np.ndarray, n_frames: int | None, zero_based: bool) -> PointFrames:
    length = int(frames.max(initial=0))
    if n_frames is not None:
        if n_frames < length:
            raise ValueError(f"{path}: frame {length} is past n_frames={n_frames}")
        length = n_frames
    order = np.argsort(frames, kind="stable")
    frames, xy = frames[order], xy[order]
    bounds = np.searchsorted(frames, np.arange(1, length + 2))
    return PointFrames([xy[bounds[k]:bounds[k + 1]].copy() for k in range(length)], path, zero_based)


def read_points_csv(path: str | os.PathLike[str], n_frames: int | None = None) -> PointFrames:
    """Points from a ``frame,x,y`` CSV (optional header; a header naming the columns, as ``frame,id,x,y`` or
    ``,t,hexbug,x,y``, picks them: :data:`COLUMN_NAMES`; extra columns ignored; 0-based when the first line is
    frame 0), padded to ``n_frames``."""
    path = Path(path)
    c = _columns(path, {"frame": 0, "x": 1, "y": 2})
    parsed, zero = _parse(path, [c["frame"], c["x"], c["y"]], pixels=1)
    data = np.array([v for _, v in parsed], dtype=float).reshape(-1, 3)
    return _group(path, data[:, 0].astype(int), data[:, 1:3], n_frames, zero)


def read_points_mot(path: str | os.PathLike[str], n_frames: int | None = None, *,
                    centre: bool = False) -> PointFrames:
    """Points from rows ``frame, id, x, y, ...`` (a header naming the columns, as ``frame,x,y,area``, picks them:
    :data:`COLUMN_NAMES`), or with ``centre=True`` the centres of MOTChallenge boxes."""
    path = Path(path)
    if not centre:
        default = {"frame": 0, "x": 2, "y": 3} if _header(path) else {"frame": 0, "id": 1, "x": 2, "y": 3}
        c = _columns(path, default)  # (an id is read, a number, only without a header, which may name none)
        parsed, zero = _parse(path, list(c.values()), pixels=len(c) - 2)
        data = np.array([v for _, v in parsed], dtype=float).reshape(-1, len(c))
        return _group(path, data[:, 0].astype(int), data[:, -2:], n_frames, zero)
    parsed, zero = _parse(path, [0, 1, 2, 3, 4, 5], pixels=2)
    data = np.array([v for _, v in parsed], dtype=float).reshape(-1, 6)
    bad = np.flatnonzero((data[:, 4:6] < 0).any(axis=1))
    if len(bad):
        raise ValueError(f"{path}:{parsed[int(bad[0])][0]}: negative box size")
    return _group(path, data[:, 0].astype(int), data[:, 2:4] + data[:, 4:6] / 2, n_frames, zero)


def read_id_points(path: str | os.PathLike[str]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(frame (n,), id (n,), xy (n, 2))`` of a ``frame,id,x,y`` file (a header naming the columns, as
    ``,t,hexbug,x,y``, picks them: :data:`COLUMN_NAMES`; 0-based when the first line is frame 0), or the box centres
    of MOTChallenge rows (7 or more columns: ``frame,id,left,top,width,height,score,...``); ``ValueError`` naming the
    file and line of a bad row."""
    path = Path(path)
    if not path.is_file():
        raise not_a_file(path)
    names = set((_header(path) or (0, []))[1])
    if {"x", "y"} <= names and not names & _BOX_NAMES:  # (x, y beside a box size: a box's corner, read as below)
        c = _columns(path, {"frame": 0, "id": 1, "x": 2, "y": 3})
        parsed, _ = _parse(path, [c["frame"], c["id"], c["x"], c["y"]], pixels=2)
    else:
        parsed, _ = _parse(path, [0, 1, 2, 3], pixels=2, extra=(4, 5, 6))
    if not parsed:
        return np.zeros(0, int), np.zeros(0, int), np.zeros((0, 2))
    width = min(len(v) for _, v in parsed)
    data = np.array([v[:width] for _, v in parsed], dtype=float)
    k = first_fraction(data[:, 1])
    if k is not None:
        raise ValueError(f"{path}:{parsed[k][0]}: invalid id: not a whole number: {data[k, 1]:g}")
    huge = np.flatnonzero(np.abs(data[:, 1]) > MAX_ID)
    if len(huge):
        raise ValueError(f"{path}:{parsed[int(huge[0])][0]}: invalid id: beyond ±2^53 = {MAX_ID}, where ids are no "
                         "longer told apart")
    order = np.lexsort((data[:, 1], data[:, 0]))
    twice = np.flatnonzero(np.all(np.diff(data[order, :2], axis=0) == 0, axis=1))
    if len(twice):
        first, second = sorted(parsed[int(order[k])][0] for k in (twice[0], twice[0] + 1))
        raise ValueError(f"{path}:{second}: id {int(data[order[twice[0]], 1])} appears twice in frame "
                         f"{int(data[order[twice[0]], 0])} (line {first} too)")
    if width < 7:
        return data[:, 0].astype(int), data[:, 1].astype(int), data[:, 2:4]
    bad = np.flatnonzero((data[:, 4:6] < 0).any(axis=1))
    if len(bad):
        raise ValueError(f"{path}:{parsed[int(bad[0])][0]}: invalid box: negative width or height")
    return data[:, 0].astype(int), data[:, 1].astype(int), data[:, 2:4] + data[:, 4:6] / 2


def typical_spacing(points: PointFrames | list[np.ndarray]) -> float:
    """Median distance from each point to its nearest neighbour in the same frame (0: never two)."""
    per_frame = points.points if isinstance(points, PointFrames) else points
    near = [_nearest(p, p, second=True) for p in per_frame if len(p) > 1]
    return float(np.median(np.concatenate(near))) if near else 0.0


def _nearest(points: np.ndarray, among: np.ndarray, second: bool = False) -> np.ndarray:
    """Distance from each of ``points (n, 2)`` to its nearest neighbour in ``among (m, 2)`` (the second nearest with
    ``second``, when ``among`` is ``points``), found with a k-d tree: memory linear in the points."""
    from scipy.spatial import cKDTree  # imported on first use

    dist, idx = cKDTree(among).query(points, k=2 if second else 1)
    if second:
        dist, idx = dist[:, 1], idx[:, 1]
    ok = np.isfinite(dist)  # the same arithmetic as a dense distance matrix, where a neighbour was found
    out: np.ndarray = np.full(len(points), np.inf)
    out[ok] = np.linalg.norm(points[ok] - among[idx[ok]], axis=1)
    return out


def typical_step(points: PointFrames | list[np.ndarray]) -> float:
    """Median distance from each point to the nearest point of the previous frame (0: none)."""
    per_frame = points.points if isinstance(points, PointFrames) else points
    near = []
    for a, b in zip(per_frame[:-1], per_frame[1:]):
        a, b = np.asarray(a, dtype=float).reshape(-1, 2), np.asarray(b, dtype=float).reshape(-1, 2)
        if len(a) and len(b):
            near.append(_nearest(b, a))
    return float(np.median(np.concatenate(near))) if near else 0.0


def points_to_rows(points: PointFrames | list[np.ndarray], box_px: float | None = None,
                   score: float = 1.0) -> np.ndarray:
    """Detection rows ``(k, 10)`` of square boxes of side ``box_px`` centred on the points (default: half the
    :func:`typical_spacing`, else twice the :func:`typical_step`, else 1)."""
    per_frame = points.points if isinstance(points, PointFrames) else points
    if box_px is None:
        spacing = typical_spacing(per_frame)
        box_px = spacing / 2 if spacing > 0 else 2 * typical_step(per_frame) or 1.0
    if not box_px > 0:
        raise ValueError(f"box_px must be > 0, got {box_px}")
    blocks = []
    for k, p in enumerate(per_frame):
        p = np.asarray(p, dtype=float).reshape(-1, 2)
        if len(p):
            blocks.append(detection_rows(k + 1, np.hstack([p - box_px / 2, np.full((len(p), 2), box_px)]), score))
    return np.vstack(blocks) if blocks else np.zeros((0, 10))


def rows_to_points(rows: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(frame (k,), id (k,), centre (k, 2))`` of result rows, as :func:`lookalike.eval.evaluate_points` takes them."""
    rows = np.asarray(rows, dtype=float).reshape(-1, np.shape(rows)[-1] if np.size(rows) else 10)
    return rows[:, 0].astype(int), rows[:, 1].astype(int), rows[:, 2:4] + rows[:, 4:6] / 2
