"""Detection files in other layouts than MOTChallenge's (a header naming the columns, corner boxes, whitespace, 0-based
frames): :func:`sniff_det` decides the layout and says what it assumed, :func:`read_det` reads it as MOTChallenge rows,
:func:`det_warnings` flags values that look wrong."""

from __future__ import annotations

import os
import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from lookalike.io.motchallenge import read_mot, row_problem
from lookalike.io.rules import DECOMPRESS_ERRORS, is_data_line, not_a_file, open_text, read_text, without_comment
from lookalike.types.mot_table import MotTable, table_from_array

MOT_COLUMNS = "frame,id,left,top,width,height,score[,x,y,z]"
EXPECTED = (f"expected MOTChallenge columns {MOT_COLUMNS} (comma- or whitespace-separated), or a header line "
            "naming the columns, or --det-format COLUMNS such as frame,x1,y1,x2,y2,score,class")
"""What a detection file should hold, for error messages."""

_ALIASES: dict[str, tuple[str, ...]] = {
    "frame": ("frame", "frame_id", "frameid", "frame_no", "f"),
    "frame0": ("frame0",),
    "id": ("id", "track_id", "trackid", "track", "object_id", "obj_id"),
    "left": ("left", "bb_left", "x1", "xmin", "x_min", "x0"),
    "top": ("top", "bb_top", "y1", "ymin", "y_min", "y0"),
    "right": ("right", "x2", "xmax", "x_max"),
    "bottom": ("bottom", "y2", "ymax", "y_max"),
    "width": ("width", "bb_width", "w"),
    "height": ("height", "bb_height", "h"),
    "score": ("score", "conf", "confidence", "prob", "probability", "det_score"),
    "class": ("class", "cls", "label", "category", "class_id"),
}
_ROLE = {alias: role for role, names in _ALIASES.items() for alias in names}
_SNIFF_LINES = 200


@dataclass(frozen=True)
class DetFormat:
    """A detection file's layout: a role per column (``-``: ignored), ``separator`` (None: whitespace), ``header``."""

    roles: tuple[str, ...]
    separator: str | None = ","
    header: bool = False

    @property
    def corners(self) -> bool:
        return "right" in self.roles

    def standard(self) -> bool:
        """True for MOTChallenge's own layout (read by :func:`~lookalike.io.read_mot` as before)."""
        return (self.separator == "," and not self.header and len(self.roles) >= 6
                and self.roles[:6] == ("frame", "id", "left", "top", "width", "height")
                and (len(self.roles) == 6 or self.roles[6] == "score"))

    def describe(self) -> str:
        """The columns as a text (corners named x1,y1,x2,y2)."""
        names = {"frame0": "frame (0-based)"}
        if self.corners:
            names.update(left="x1", top="y1", right="x2", bottom="y2")
        return ",".join(names.get(r, r) for r in self.roles)


MOT = DetFormat(("frame", "id", "left", "top", "width", "height", "score", "-", "-", "-"))


def parse_columns(text: str, where: str = "--det-format", separator: str | None = "any") -> tuple[str, ...]:
    """Roles of a list of column names (``_ALIASES``, quotes dropped); ``ValueError`` naming ``where`` without frame
    and box. ``separator``: ``any`` (commas, semicolons, whitespace), or a file's (None: whitespace), where an empty
    name (a spreadsheet's unnamed index column) is a column skipped."""
    parts = [n for n in re.split(r"[,\s;]+", text.strip()) if n.strip()] if separator == "any" else \
        _split(text, separator)
    names = [n.strip().strip("\"'").lower() for n in parts]
    roles = [_ROLE.get(n, "-") for n in names]
    if "left" not in roles and "top" not in roles:  # x, y name the corner only where nothing else does
        roles = ["left" if n == "x" else "top" if n == "y" else r for n, r in zip(names, roles)]
    for role in set(roles) - {"-"}:
        if roles.count(role) > 1:
            raise ValueError(f"{where}: column {role!r} named twice in {text.strip()!r}; {EXPECTED}")
    has_box = {"left", "top"} <= set(roles) and ({"width", "height"} <= set(roles) or {"right", "bottom"} <= set(roles))
    if not ({"frame", "frame0"} & set(roles)) or not has_box:
        raise ValueError(f"{where}: no frame and box columns in {text.strip()!r}; {EXPECTED}")
    return tuple(roles)


def _split(line: str, separator: str | None) -> list[str]:
    return [f.strip() for f in line.split(separator)] if separator else line.split()


def _numbers(fields: list[str]) -> list[float] | None:
    try:
        return [float(f) for f in fields]
    except ValueError:
        return None


def _integral(values: np.ndarray) -> bool:
    return bool(np.all(np.isfinite(values)) and np.all(values == np.round(values)))


def _guess_roles(sample: np.ndarray) -> tuple[tuple[str, ...], str | None]:
    """Roles of header-less rows ``sample`` ``(k, c)`` and why they were chosen (None: MOTChallenge's own)."""
    width = sample.shape[1]
    mot = MOT.roles[:width] + ("-",) * max(0, width - len(MOT.roles))
    if width < 6 or np.all(sample[:, 1] == -1):
        return mot, None
    x1, y1, x2, y2 = sample[:, 1], sample[:, 2], sample[:, 3], sample[:, 4]
    corners = bool(np.all(x2 > x1) and np.all(y2 > y1))
    score_col = width >= 6 and bool(np.all((sample[:, 5] >= 0) & (sample[:, 5] <= 1)))
    class_col = width < 7 or _integral(sample[:, 6])
    mot_unlikely = not _integral(sample[:, 1]) or bool(np.all(sample[:, 5] <= 1))  # an id, a height in pixels
    if corners and score_col and class_col and mot_unlikely:
        roles = ("frame", "left", "top", "right", "bottom", "score") + (("class",) if width > 6 else ())
        return roles + ("-",) * (width - len(roles)), ("no id column, boxes as corners x1,y1,x2,y2 (column 2 is "
                                                       "not an id, column 6 is a score in [0, 1])")
    return mot, None


def _first_lines(path: Path) -> list[str]:
    """The first :data:`_SNIFF_LINES` data lines of ``path`` (:func:`~lookalike.io.rules.is_data_line`)."""
    lines = []
    try:
        with open_text(path) as fh:
            for line in fh:
                if is_data_line(line):
                    lines.append(line)
                    if len(lines) >= _SNIFF_LINES:
                        break
    except (UnicodeDecodeError, *DECOMPRESS_ERRORS):
        read_text(path)  # a binary file (a video given as detections) or a damaged gzip: named, never sniffed
        raise
    if any("\0" in line for line in lines):
        read_text(path)  # (refuses the NUL character, naming its line)
    return lines


def _refuse_semicolons(path: Path, first: str) -> None:
    """``ValueError`` for a first line of six or more columns separated by ``;`` (a spreadsheet's export, its numbers
    perhaps with decimal commas), which would read as one column, or as a header naming none."""
    if len(without_comment(first).split(";")) >= 6:
        raise ValueError(f"{path}:1: columns separated by ';' (decimal commas?) in {first.strip()[:80]!r}; {EXPECTED}, "
                         "with decimal points")


def sniff_det(path: str | os.PathLike[str], spec: str = "auto") -> tuple[DetFormat, list[str]]:
    """The layout of detection file ``path`` and notes on what was assumed; ``spec``: ``auto`` (from the first lines),
    ``mot`` (separator and header still detected) or column names (``frame,x1,y1,x2,y2,score,class``; ``frame0``:
    0-based). ``ValueError`` when the lines cannot be read as detections."""
    path = Path(path)
    if not path.is_file():
        raise not_a_file(path)
    lines = _first_lines(path)
    if not lines:
        return MOT, []
    first = lines[0]
    separator = "," if "," in first else None
    notes = [] if separator == "," else ["whitespace-separated columns"]
    header = all(_numbers([f]) is None for f in _split(first, separator) if f)  # names only, no number
    _refuse_semicolons(path, first)
    rows = lines[1:] if header else lines
    sample = [p for p in (_numbers(_split(ln, separator)) for ln in rows) if p is not None]
    if spec not in ("auto", "mot"):
        roles, note = parse_columns(spec), f"columns read as {DetFormat(parse_columns(spec)).describe()} (--det-format)"
    elif header and spec == "auto":
        roles = parse_columns(first, f"{path}:1 (header line)", separator)
        note = f"header line: columns read as {DetFormat(roles).describe()}"
    else:
        width = min((len(p) for p in sample), default=len(MOT.roles))
        if width < 6:
            if separator == ",":
                return MOT, []  # read_mot says which line and what it expects
            raise ValueError(f"{path}: {width} column(s) per line; {EXPECTED}")
        roles, why = MOT.roles[:width] + ("-",) * max(0, width - len(MOT.roles)), None
        if spec == "auto" and sample:
            roles, why = _guess_roles(np.array([p[:width] for p in sample]))
        note = f"columns read as {DetFormat(roles).describe()}: {why}" if why else ""
    if note:
        notes.append(note)
    if header and spec != "auto":
        notes.append("first line skipped (a header)")
    if "frame" in roles and sample and len(sample[0]) > roles.index("frame") and sample[0][roles.index("frame")] == 0:
        roles = tuple("frame0" if r == "frame" else r for r in roles)
        notes.append("frames start at 0: read as 0-based (file frame 0 is the first frame)")
    return DetFormat(roles, separator, header), notes


def read_det(path: str | os.PathLike[str], fmt: DetFormat, length: int | None = None,
             length_name: str = "the length") -> MotTable:
    """The detections of ``path`` in layout ``fmt`` as a MOTChallenge table (score 1 without a score column);
    ``ValueError`` naming file and line for what :func:`~lookalike.io.read_mot` would refuse."""
    path = Path(path)
    need = max(i for i, r in enumerate(fmt.roles) if r != "-") + 1
    numbers: list[list[float]] = []
    line_nos: list[int] = []
    for line_no, line in enumerate(read_text(path).splitlines(), start=1):
        if not is_data_line(line):
            continue
        if fmt.header and not line_nos and not numbers and _numbers(_split(line, fmt.separator)) is None:
            fmt = DetFormat(fmt.roles, fmt.separator, False)  # the header: skipped once
            continue
        fields = _split(without_comment(line), fmt.separator)
        values = _numbers(fields[:need]) if len(fields) >= need else None
        if values is None:
            what = f"{len(fields)} column(s)" if len(fields) < need else "not a number"
            raise ValueError(f"{path}:{line_no}: {what} in {line.strip()[:80]!r}; columns read as "
                             f"{fmt.describe()}; {EXPECTED}")
        numbers.append(values)
        line_nos.append(line_no)
    data = np.array(numbers, dtype=float).reshape(len(numbers), need)
    col = {r: data[:, i] for i, r in enumerate(fmt.roles[:need]) if r != "-"}
    n = len(data)
    frame = col["frame0"] + 1 if "frame0" in col else col["frame"]
    left, top = col["left"], col["top"]
    width = col["right"] - left if "right" in col else col["width"]
    height = col["bottom"] - top if "bottom" in col else col["height"]
    rows = np.column_stack([frame, col.get("id", np.full(n, -1.0)), left, top, width, height,
                            col.get("score", np.ones(n)), np.full((n, 3), -1.0)]) if n else np.zeros((0, 10))
    problem = row_problem(rows, length=length, length_name=length_name, positive_size=True)
    if problem is not None:
        line_no = line_nos[problem[0]]
        raise ValueError(f"{path}:{line_no}: {problem[1]} (columns read as {fmt.describe()})")
    return table_from_array(rows, path)


def read_detections(path: str | os.PathLike[str], spec: str = "auto") -> tuple[MotTable, list[str]]:
    """The detections of ``path`` in any layout ``lookalike track`` reads (:func:`sniff_det`; ``spec`` as there) and
    the notes on what was assumed; ``ValueError`` naming file and line as :func:`read_det` (sizes must be > 0)."""
    fmt, notes = sniff_det(path, spec)
    table = read_mot(path, positive_size=True) if fmt.standard() else read_det(path, fmt)
    return table, notes


def det_warnings(path: Path | str, count: int, scores: tuple[float, float] | None, outside: int,
                 image_size: tuple[int, int] | None, size_from: str = "", largest: float | None = None) -> list[str]:
    """Warnings: ``outside`` of ``count`` boxes centred outside ``image_size`` (from ``size_from``), every score
    equal (``scores``: lowest and highest), or no box wider or higher than 1 px (``largest``: the largest side, px):
    coordinates normalised to [0, 1]."""
    found = []
    if count and largest is not None and largest <= 1:
        found.append(f"{path}: no box is wider or higher than 1 px: are the coordinates normalised to [0, 1]? "
                     "Boxes are in pixels: multiply left and width by the image width, top and height by its height")
    if outside and image_size is not None:
        found.append(f"{path}: {outside} of {count} boxes are centred outside the {image_size[0]}x{image_size[1]} "
                     f"frame{f' ({size_from})' if size_from else ''}; are the columns {MOT_COLUMNS}? "
                     "(--det-format names them)")
    if count > 1 and scores is not None and scores[0] == scores[1]:
        what = "zero" if scores[0] == 0 else f"{scores[0]:g}"
        found.append(f"{path}: every score is {what}: is the score column the right one? (--min-score and the "
                     "trackers' score thresholds see no difference between boxes)")
    return found


def largest_side(xywh: np.ndarray) -> float:
    """The largest width or height of boxes ``(n, 4)`` px (0 without boxes)."""
    return float(np.max(xywh[:, 2:4])) if len(xywh) else 0.0


def box_stats(xywh: np.ndarray, conf: np.ndarray, image_size: tuple[int, int] | None) -> tuple[
        tuple[float, float] | None, int]:
    """``(lowest, highest)`` score (None without boxes) and the number of boxes centred outside ``image_size``."""
    if not len(conf):
        return None, 0
    outside = 0
    if image_size is not None:
        cx, cy = xywh[:, 0] + xywh[:, 2] / 2, xywh[:, 1] + xywh[:, 3] / 2
        outside = int(np.count_nonzero((cx < 0) | (cy < 0) | (cx > image_size[0]) | (cy > image_size[1])))
    return (float(conf.min()), float(conf.max())), outside


__all__ = ["EXPECTED", "MOT", "MOT_COLUMNS", "DetFormat", "box_stats", "det_warnings", "largest_side", "parse_columns",
           "read_det", "read_detections", "sniff_det"]
