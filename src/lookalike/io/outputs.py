"""Where results go, checked before anything runs (:func:`check_outputs`: never onto an input, never two outputs onto
one file, a writable folder), and files written through a temporary file renamed into place (:func:`atomic_path`)."""

from __future__ import annotations

import errno
import os
from collections.abc import Collection, Iterable, Iterator, Mapping, Sequence
from contextlib import contextmanager
from pathlib import Path

from lookalike.io.rules import is_special, temp_beside, write_target
from lookalike.io.sequences import MotSequence


def _same_file(a: Path, b: Path) -> bool:
    """Whether ``a`` and ``b`` are one file (symbolic links and hard links followed)."""
    try:
        if a.exists() and b.exists():
            return os.path.samefile(a, b)
        return a.resolve() == b.resolve()
    except OSError:
        return False


def _inside(path: Path, folder: Path) -> bool:
    """Whether ``path`` resolves to a place inside ``folder`` (resolved)."""
    try:
        return path.resolve().is_relative_to(folder.resolve())
    except OSError:
        return False


def check_outputs(outputs: Mapping[str, Path | None], inputs: Iterable[Path | None] = (), *,
                  folders: Collection[str] = (), input_folders: Iterable[Path | None] = ()) -> None:
    """Check a command's ``outputs`` (option name -> path or None) and create their folders; ``ValueError`` naming
    the option and path when an output is one of ``inputs`` (links followed) or an existing file in ``input_folders``,
    two outputs are one file, an output is a folder (one named in ``folders``: a file), or cannot be written."""
    given = [(name, Path(p)) for name, p in outputs.items() if p is not None]
    for i, (name, path) in enumerate(given):
        for other, other_path in given[:i]:
            if _same_file(path, other_path):
                raise ValueError(f"{other} {other_path} and {name} {path} are one file; give each output its own "
                                 "path (nothing was written)")
    files = [Path(p) for p in inputs if p is not None and not Path(p).is_dir()]
    dirs = [Path(p) for p in input_folders if p is not None and Path(p).is_dir()]
    for name, path in given:
        for src in files:
            if _same_file(path, src):
                raise ValueError(f"{name} {path} is the input {src}; choose another output (nothing was written)")
        if path.is_file():
            for folder in dirs:
                if _inside(path, folder):
                    raise ValueError(f"{name} {path} would replace a file in the input folder {folder}; choose "
                                     "another output (nothing was written)")
        if name in folders and path.exists() and not path.is_dir():
            raise ValueError(f"{name} {path}: is a file, not a folder (nothing was written)")
        if name not in folders and path.is_dir():
            raise ValueError(f"{name} {path} is a folder; expected a file (nothing was written)")
        try:
            _check_folder(path if name in folders else path.parent)
        except ValueError as exc:
            raise ValueError(f"{name} {path}: {exc}") from None


def _check_folder(folder: Path) -> None:
    """Create ``folder`` (and its parents); ``ValueError`` naming it when it cannot be created or written."""
    if folder.exists() and not folder.is_dir():
        raise ValueError(f"output folder {folder}: is a file, not a folder")
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise ValueError(f"output folder {folder}: cannot be created ({exc.strerror or exc})") from None
    if not os.access(folder, os.W_OK | os.X_OK):
        raise ValueError(f"output folder {folder}: not writable (permission denied)")


@contextmanager
def atomic_path(path: str | os.PathLike[str]) -> Iterator[Path]:
    """A temporary file (:func:`~lookalike.io.rules.temp_beside`) to write instead of ``path``: renamed onto ``path``
    (onto the file a symbolic link points at) when the block ends, removed when it raises (``KeyboardInterrupt`` and
    SIGTERM's ``SystemExit`` included). A device or named pipe (``/dev/null``) is itself written into; an existing
    folder raises ``IsADirectoryError`` naming ``path``, before anything is written."""
    target = write_target(Path(path))
    if is_special(target):
        yield target
        return
    if target.is_dir():  # (else the rename failed naming the temporary file)
        raise IsADirectoryError(errno.EISDIR, "is a folder; give a file name", str(path))
    target.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = temp_beside(target)
    try:
        os.close(fd)
        yield tmp
        os.replace(tmp, target)
    finally:
        tmp.unlink(missing_ok=True)


def write_atomic(path: str | os.PathLike[str], data: str | bytes) -> Path:
    """Write ``data`` (text as UTF-8) to ``path`` through :func:`atomic_path`; returns the path."""
    with atomic_path(path) as tmp:
        tmp.write_bytes(data.encode("utf-8") if isinstance(data, str) else data)
    return Path(path)


def refuse_inputs(outputs: Iterable[Path], inputs: Iterable[Path | None]) -> None:
    """``ValueError`` when an output is (or resolves to) one of the ``inputs``."""
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
    """The result file of each of ``sequences`` read from ``path``: ``output`` for a single detection file, else
    ``output/<sequence name>.txt``; ``ValueError`` for a folder/file mismatch, two sequences with one name (ignoring
    case) or an output that is an input."""
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
    """Create the folders of ``targets``; ``ValueError`` when one cannot be written or a target is a folder."""
    for folder in dict.fromkeys(Path(t).parent for t in targets):
        _check_folder(folder)
    for t in targets:
        if Path(t).is_dir():
            raise ValueError(f"output {t} is a folder; expected a result file")


def sqlite_file(url: str | None) -> Path | None:
    """The database file of an SQLite storage URL (``sqlite:///PATH``), else None."""
    if url is None or not url.startswith("sqlite:///") or url.endswith(":memory:"):
        return None
    return Path(url[len("sqlite:///"):])


__all__ = ["atomic_path", "check_outputs", "ensure_writable", "refuse_inputs", "result_paths", "sequence_inputs",
           "sqlite_file", "write_atomic"]
