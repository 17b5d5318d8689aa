"""MOTChallenge sequence folders: ``seqinfo.ini``, ``det/det.txt``, ``gt/gt.txt``."""

from __future__ import annotations

import configparser
import os
from dataclasses import dataclass
from pathlib import Path


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
        image_size: ``(width, height)`` in pixels, or None.
    """

    name: str
    root: Path | None
    det_path: Path | None
    gt_path: Path | None
    frame_rate: float = 30.0
    length: int | None = None
    image_size: tuple[int, int] | None = None


def read_seqinfo(path: str | os.PathLike[str]) -> dict[str, str]:
    """The ``[Sequence]`` section of a ``seqinfo.ini`` as a dict (keys as written)."""
    path = Path(path)
    parser = configparser.ConfigParser()
    parser.optionxform = str  # type: ignore[assignment,method-assign]  # keep key case
    try:
        parser.read_string(path.read_text(), source=str(path))
    except configparser.Error as exc:
        raise ValueError(f"{path}: malformed seqinfo.ini ({exc})") from None
    if "Sequence" not in parser:
        raise ValueError(f"{path}: no [Sequence] section")
    return dict(parser["Sequence"])


def _sequence_from_folder(folder: Path) -> MotSequence:
    det = folder / "det" / "det.txt"
    gt = folder / "gt" / "gt.txt"
    info_path = folder / "seqinfo.ini"
    name, rate, length, size = folder.name, 30.0, None, None
    if info_path.is_file():
        info = read_seqinfo(info_path)
        try:
            name = info.get("name", name)
            rate = float(info.get("frameRate", rate))
            length = int(info["seqLength"]) if "seqLength" in info else None
            if "imWidth" in info and "imHeight" in info:
                size = (int(info["imWidth"]), int(info["imHeight"]))
        except ValueError as exc:
            raise ValueError(f"{info_path}: {exc}") from None
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

    A bare ``det.txt`` inside ``<seq>/det/`` picks up that sequence's ``seqinfo.ini``.
    """
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
