"""Human-benchmark result files, ``<sequence stem>.human-<labeller>.json``, written by a finished ``lookalike label
--benchmark`` session and read by ``lookalike bench ident --lengths``: sequence, labeller, Unix times, counts and
success rates (:func:`~lookalike.viz.label.store.score_labels`)."""

from __future__ import annotations

import json
import re
from collections.abc import Mapping
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

from lookalike.io.outputs import write_atomic

FORMAT = "lookalike-human-benchmark"
VERSION = 1
RESULT_GLOB = "*.human-*.json"
_LABELLER = re.compile(r"[A-Za-z0-9][A-Za-z0-9._-]{0,63}")


def check_labeller(labeller: str) -> str:
    """``labeller`` if it is a usable id (1-64 letters, digits, ``.``, ``_``, ``-``), else ``ValueError``."""
    if not isinstance(labeller, str) or not _LABELLER.fullmatch(labeller):
        raise ValueError(f"--labeller: {labeller!r} is not a labeller id (1-64 letters, digits, '.', '_', '-')")
    return labeller


def human_result_path(sequence_path: str | Path, labeller: str, folder: str | Path | None = None) -> Path:
    """Where the session of ``labeller`` on the sequence writes its result (default: beside the sequence)."""
    sequence_path = Path(sequence_path)
    base = Path(folder) if folder is not None else sequence_path.parent
    return base / f"{sequence_path.stem}.human-{check_labeller(labeller)}.json"


@dataclass(frozen=True)
class HumanResult:
    """One finished human-benchmark session (fields as in the module docstring)."""

    sequence: str
    labeller: str
    n_agents: int
    max_detections: int
    n_frames: int
    started_at: float
    finished_at: float
    duration_s: float
    frames_scored: int
    detections_scored: int
    correct: int
    unset: int
    success_rate: float | None
    success_rate_all: float | None

    @property
    def seconds_per_frame(self) -> float | None:
        """Labelling time per frame worked through (s), None when no frame was."""
        return self.duration_s / self.frames_scored if self.frames_scored > 0 else None


def human_result(sequence_name: str, labeller: str, n_agents: int, max_detections: int, n_frames: int,
                 benchmark: Mapping[str, Any]) -> HumanResult:
    """The result of a finished session from the label file's ``benchmark`` entry."""
    if benchmark.get("finished_at") is None:
        raise ValueError("the benchmark session has not finished")
    return HumanResult(
        sequence=sequence_name, labeller=check_labeller(labeller), n_agents=int(n_agents),
        max_detections=int(max_detections), n_frames=int(n_frames), started_at=float(benchmark["started_at"]),
        finished_at=float(benchmark["finished_at"]), duration_s=float(benchmark["duration_s"]),
        frames_scored=int(benchmark["frames_scored"]), detections_scored=int(benchmark["detections_scored"]),
        correct=int(benchmark["correct"]), unset=int(benchmark["unset"]),
        success_rate=_rate(benchmark.get("success_rate")), success_rate_all=_rate(benchmark.get("success_rate_all")))


def write_human_result(path: str | Path, result: HumanResult) -> Path:
    """Write ``result`` to ``path`` atomically (folders created); returns the path."""
    return write_atomic(path, json.dumps({"format": FORMAT, "version": VERSION, **asdict(result)}, indent=1) + "\n")


def read_human_result(path: str | Path) -> HumanResult:
    """One result file; ``ValueError`` naming the file when it is not one."""
    path = Path(path)
    try:
        data = json.loads(path.read_text())
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise ValueError(f"{path}: not a readable human-benchmark result ({exc})") from None
    if not isinstance(data, dict) or data.get("format") != FORMAT or data.get("version") != VERSION:
        raise ValueError(f"{path}: not a {FORMAT} v{VERSION} file")
    fields = HumanResult.__dataclass_fields__
    missing = [f for f in fields if f not in data]
    if missing:
        raise ValueError(f"{path}: missing {', '.join(missing)}")
    try:
        result = human_result(data["sequence"], data["labeller"], data["n_agents"], data["max_detections"],
                              data["n_frames"], data)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"{path}: {exc}") from None
    if not 0 <= result.correct <= result.detections_scored or not 0 <= result.frames_scored <= result.n_frames:
        raise ValueError(f"{path}: inconsistent counts (correct {result.correct} of {result.detections_scored}, "
                         f"{result.frames_scored} of {result.n_frames} frames)")
    return result


def read_human_results(folder: str | Path) -> list[HumanResult]:
    """Every result file (``*.human-*.json``) in ``folder``, by file name; none when the folder has none."""
    folder = Path(folder)
    if not folder.is_dir():
        raise ValueError(f"--human: {folder} is not a folder")
    return [read_human_result(p) for p in sorted(folder.glob(RESULT_GLOB))]


def _rate(value: Any) -> float | None:
    if value is None:
        return None
    rate = float(value)
    if not 0.0 <= rate <= 1.0:
        raise ValueError(f"success rate {rate} outside 0..1")
    return rate


__all__ = ["FORMAT", "RESULT_GLOB", "VERSION", "HumanResult", "check_labeller", "human_result", "human_result_path",
           "read_human_result", "read_human_results", "write_human_result"]
