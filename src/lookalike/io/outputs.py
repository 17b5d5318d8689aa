"""Where results go, decided before anything runs: one file per sequence, never onto an input, never two sequences onto
one file, a writable folder. Refusals are one-line ``ValueError``s."""

from __future__ import annotations

import os
from collections.abc import Iterable, Sequence
from pathlib import Path

from lookalike.io.sequences import MotSequence


def _same_file(a: Path, b: Path) -> bool:
    """Whether ``a`` and ``b`` are one file (symbolic links and hard links followed)."""
    try:
        if a.exists() and b.exists():
            return os.path.samefile(a, b)
        return a.resolve() == b.resolve()
    except OSError:
        return False


def refuse_inputs(outputs: Iterable[Path], inputs: Iterable[Path | None]) -> None:
    """``ValueError`` when an output is (or resolves to) one of the ``inputs``: the run would
    overwrite its own input."""
    files = [Path(p) for p in inputs if p is not None]
    for out in outputs:
        for src in files:
            if _same_file(out, src):
                raise ValueError(f"output {out} is the input {src}; choose another output (nothing was written)")


def sequence_inputs(sequences: Iterable[MotSequence]) -> list[Path]:
    """Every file a sequence is read from: detections, ground truth and ``seqinfo.ini``."""
    out: list[Path] = []
    for s in sequences:
        out += [p for p in (s.det_path, s.gt_path) if p is not None]
        if s.root is not None and (s.root / "seqinfo.ini").is_file():
            out.append(s.root / "seqinfo.ini")
    return out


def result_paths(path: Path, sequences: Sequence[MotSequence], output: Path) -> list[Path]:
    """The result file of each of ``sequences`` read from ``path``: ``output`` itself for a single
    detection file, else ``output/<sequence name>.txt``. Refused (``ValueError``): ``output`` a folder
    for a single file or an existing file for a folder of sequences; two sequences with one name
    (compared ignoring case, for case-insensitive file systems); an output that is an input file."""
    if path.is_file():
        if output.is_dir():
            raise ValueError(f"output {output} is a folder; a single detection file is tracked into one result "
                             f"file, e.g. {output / (sequences[0].name + '.txt')}")
        targets = [output]
    else:
        if output.exists() and not output.is_dir():
            raise ValueError(f"output {output} is a file; a folder of sequences is tracked into a folder "
                             "(one <sequence>.txt each)")
        seen: dict[str, MotSequence] = {}
        for seq in sequences:
            other = seen.setdefault(seq.name.casefold(), seq)
            if other is not seq:
                raise ValueError(f"two sequences are named {seq.name!r} ({other.root} and {seq.root}; the name "
                                 "comes from seqinfo.ini): their results would overwrite each other")
        targets = [output / f"{seq.name}.txt" for seq in sequences]
    refuse_inputs(targets, sequence_inputs(sequences))
    return targets


def ensure_writable(targets: Iterable[Path]) -> None:
    """Create the folders of ``targets`` and check that files can be created there (``ValueError``
    naming the folder otherwise), and that no target is an existing folder."""
    for folder in dict.fromkeys(Path(t).parent for t in targets):
        if folder.exists() and not folder.is_dir():
            raise ValueError(f"output folder {folder}: is a file, not a folder")
        try:
            folder.mkdir(parents=True, exist_ok=True)
        except OSError as exc:
            raise ValueError(f"output folder {folder}: cannot be created ({exc.strerror or exc})") from None
        if not os.access(folder, os.W_OK | os.X_OK):
            raise ValueError(f"output folder {folder}: not writable (permission denied)")
    for t in targets:
        if Path(t).is_dir():
            raise ValueError(f"output {t} is a folder; expected a result file")


__all__ = ["ensure_writable", "refuse_inputs", "result_paths", "sequence_inputs"]
