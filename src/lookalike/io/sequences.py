"""MOTChallenge sequence folders: ``seqinfo.ini``, ``det/det.txt``, ``gt/gt.txt``."""

from __future__ import annotations

import configparser
import math
import os
from dataclasses import dataclass
from pathlib import Path

from lookalike.io.rules import read_text


@dataclass(frozen=True)
class MotSequence:
    """One sequence on disk.

    Attributes:
        name: sequence name (folder name, or the ``name`` in ``seqinfo.ini``).
        root: the sequence folder (None for a bare detection file).
        det_path: the detection file, or None.
        gt_path: the ground-truth file, or None.
        frame_rate: frames per second (30 when unknown).
        length: number of frames, or None when unknown (then the last detected frame).
        image_size: ``(width, height)`` in pixels, or None."""

    name: str
    root: Path | None
    det_path: Path | None
    gt_path: Path | None
    frame_rate: float = 30.0
    length: int | None = None
    image_size: tuple[int, int] | None = None


def read_seqinfo(path: str | os.PathLike[str]) -> dict[str, str]:
    """The ``[Sequence]`` section of a ``seqinfo.ini`` as a dict (keys as written); ``ValueError``
    naming the file when it is not UTF-8 text, malformed, or has no such section."""
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
    """The sequence in ``folder``; its ``seqinfo.ini`` (if any) is checked: ``seqLength``, ``imWidth``,
    ``imHeight`` integers >= 1, ``frameRate`` a positive number, ``name`` a plain file name."""
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
    return MotSequence(
        name=name,
        root=folder,
        det_path=det if det.is_file() else None,
        gt_path=gt if gt.is_file() else None,
        frame_rate=rate,
        length=length,
        image_size=size,
    )


def _is_sequence(folder: Path) -> bool:
    return (folder / "seqinfo.ini").is_file() or (folder / "det").is_dir() or (folder / "gt").is_dir()


def find_sequences(path: str | os.PathLike[str]) -> list[MotSequence]:
    """Sequences at ``path``: a detection file, one sequence folder, or a folder of them.

    A bare ``det.txt`` inside ``<seq>/det/`` picks up that sequence's ``seqinfo.ini``."""
    path = Path(path)
    if path.is_file():
        parent = path.parent.parent if path.parent.name == "det" else None
        if parent is not None and _is_sequence(parent):
            seq = _sequence_from_folder(parent)
            return [MotSequence(seq.name, seq.root, path, seq.gt_path, seq.frame_rate, seq.length, seq.image_size)]
        return [MotSequence(path.stem, None, path, None)]
    if not path.is_dir():
        raise FileNotFoundError(f"{path}: no such file or folder")
    if _is_sequence(path):
        return [_sequence_from_folder(path)]
    found = [_sequence_from_folder(p) for p in sorted(path.iterdir()) if p.is_dir() and _is_sequence(p)]
    if not found:
        raise ValueError(
            f"{path}: neither a sequence folder (seqinfo.ini, det/ or gt/) nor a folder of sequences"
        )
    return found
