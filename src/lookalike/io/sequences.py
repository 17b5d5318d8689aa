"""MOTChallenge sequence folders: ``seqinfo.ini``, ``det/det.txt``, ``gt/gt.txt``."""

from __future__ import annotations

import configparser
import math
import os
from dataclasses import dataclass, replace
from pathlib import Path

from lookalike.io.rules import read_text


@dataclass(frozen=True)
class MotSequence:
    """One sequence on disk: ``name`` (folder's, or ``seqinfo.ini``'s), ``root`` folder (None: a bare file), the
    detection and ground-truth files, frames per second, ``length`` in frames and ``(width, height)`` px if known."""

    name: str
    root: Path | None
    det_path: Path | None
    gt_path: Path | None
    frame_rate: float = 30.0
    length: int | None = None
    image_size: tuple[int, int] | None = None


def read_seqinfo(path: str | os.PathLike[str]) -> dict[str, str]:
    """The ``[Sequence]`` section of a ``seqinfo.ini`` (keys as written); ``ValueError`` naming the file."""
    path = Path(path)
    parser = configparser.ConfigParser(interpolation=None)
    parser.optionxform = str  # type: ignore[assignment,method-assign]  # keep key case
    try:
        parser.read_string(read_text(path), source=str(path))
    except configparser.Error as exc:
        errors = getattr(exc, "errors", None)
        line = errors[0][0] if errors else getattr(exc, "lineno", None)
        where = f"{path}:{line}" if line else str(path)
        detail = " ".join(str(exc).replace(str(path), "").split())[:120]
        raise ValueError(f"{where}: malformed seqinfo.ini ({detail})") from None
    if "Sequence" not in parser:
        raise ValueError(f"{path}: no [Sequence] section")
    return dict(parser["Sequence"])


def _positive_int(info: dict[str, str], key: str, path: Path) -> int:
    text = info[key].strip()
    try:
        value = int(text)
    except ValueError:
        value = 0
    if value < 1:
        raise ValueError(f"{path}: {key} must be an integer >= 1, got {text!r}")
    return value


def _frame_rate(info: dict[str, str], path: Path) -> float:
    text = info["frameRate"].strip()
    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not (math.isfinite(value) and value > 0):
        raise ValueError(f"{path}: frameRate must be a positive number (frames per second), got {text!r}")
    return value


def _plain_name(name: str, path: Path) -> str:
    """``name`` if it can name a result file (``<name>.txt``): not empty, no folder separators."""
    if not name.strip() or name in (".", "..") or any(c in name for c in "/\\\0") or name != name.strip():
        raise ValueError(f"{path}: name must be a plain file name (no '/', not empty), got {name!r}")
    return name


def _sequence_from_folder(folder: Path) -> MotSequence:
    """The sequence in ``folder``, with its ``seqinfo.ini`` (if any) checked."""
    det = folder / "det" / "det.txt"
    gt = folder / "gt" / "gt.txt"
    info_path = folder / "seqinfo.ini"
    name, rate, length, size = folder.name, 30.0, None, None
    if info_path.is_file():
        info = read_seqinfo(info_path)
        name = _plain_name(info.get("name", name), info_path)
        rate = _frame_rate(info, info_path) if "frameRate" in info else rate
        length = _positive_int(info, "seqLength", info_path) if "seqLength" in info else None
        if "imWidth" in info and "imHeight" in info:
            size = (_positive_int(info, "imWidth", info_path), _positive_int(info, "imHeight", info_path))
    return MotSequence(name, folder, det if det.is_file() else None, gt if gt.is_file() else None, rate, length, size)


def _is_sequence(folder: Path) -> bool:
    return (folder / "seqinfo.ini").is_file() or (folder / "det").is_dir() or (folder / "gt").is_dir()


def find_sequences(path: str | os.PathLike[str]) -> list[MotSequence]:
    """Sequences at ``path``: a detection file, one sequence folder, or a folder of them."""
    path = Path(path)
    if path.is_file():
        parent = path.parent.parent if path.parent.name == "det" else None
        if parent is not None and _is_sequence(parent):
            return [replace(_sequence_from_folder(parent), det_path=path)]
        return [MotSequence(path.stem, None, path, None)]
    if not path.is_dir():
        raise FileNotFoundError(f"{path}: no such file or folder")
    if _is_sequence(path):
        return [_sequence_from_folder(path)]
    found = [_sequence_from_folder(p) for p in sorted(path.iterdir()) if p.is_dir() and _is_sequence(p)]
    if not found:
        raise ValueError(f"{path}: neither a sequence folder (seqinfo.ini, det/ or gt/) nor a folder of sequences")
    return found
