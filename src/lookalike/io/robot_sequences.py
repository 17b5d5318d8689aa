"""Simulated robot sequences as JSON Lines: a header line::

    {"format": "lookalike-robots", "version": 1, "seed": 900000, "n_frames": 1000,
     "reports_sent": 29870, "config": {...RobotWorldConfig as nested objects...}}

then one line per frame, in order::

    {"frame": 0, "time": 0.0,
     "detections": {"position": [[x, y], ...], "heading": [...], "score": [...], "label": [...]},
     "beacons": {"agent_id": [...], "t_sent": [...], "t_received": [...], "heading": [...]},
     "truth": {"position": [[x, y] x N], "heading": [N], "visible": [N], "occlusion": [N],
               "field_position": [[x, y] x N], "observer": [x, y, yaw],
               "n_false_positives": 1, "n_misses": 0}}

Metres (detections and ``truth.position`` in the observer frame: x forward, y left; the rest in field coordinates),
radians, seconds; ``label``: agent id or -1 (a false positive). Floats at full precision: reading is exact."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np

from lookalike.io.rules import read_text
from lookalike.sim import ReportArrays, RobotArrays, RobotSequence, RobotWorldConfig

FORMAT = "lookalike-robots"
VERSION = 1
MAX_AGENTS = 1_000  # a header claiming more agents or detection slots is refused before allocating
MAX_DETECTIONS = 10_000


def write_robot_sequence(path: str | Path, sequence: RobotSequence) -> Path:
    """Write ``sequence`` to ``path`` (atomically: a temporary file renamed); returns the path."""
    from lookalike.io.outputs import atomic_path

    path = Path(path)
    a, r = sequence.arrays, sequence.arrays.reports
    header = {"format": FORMAT, "version": VERSION, "seed": sequence.seed, "n_frames": len(a),
              "reports_sent": r.n_sent, "config": sequence.config.to_dict()}
    with atomic_path(path) as tmp, tmp.open("w") as fh:
        fh.write(json.dumps(header) + "\n")
        for k in range(len(a)):
            n = int(a.det_valid[k].sum())
            lo, hi = r.frame_offsets[k], r.frame_offsets[k + 1]
            row = {
                "frame": k, "time": float(a.time[k]),
                "detections": {"position": a.det_position[k, :n].tolist(), "heading": a.det_heading[k, :n].tolist(),
                               "score": a.det_score[k, :n].tolist(), "label": a.det_label[k, :n].tolist()},
                "beacons": {"agent_id": r.agent_id[lo:hi].tolist(), "t_sent": r.t_sent[lo:hi].tolist(),
                            "t_received": r.t_received[lo:hi].tolist(), "heading": r.heading[lo:hi].tolist()},
                "truth": {"position": a.true_position[k].tolist(), "heading": a.true_heading[k].tolist(),
                          "visible": a.visible[k].tolist(), "occlusion": a.occlusion[k].tolist(),
                          "field_position": a.field_position[k].tolist(), "observer": a.observer[k].tolist(),
                          "n_false_positives": int(a.n_false_positives[k]), "n_misses": int(a.n_misses[k])},
            }
            fh.write(json.dumps(row) + "\n")
    return path


def read_robot_sequence(path: str | Path) -> RobotSequence:
    """Read a :func:`write_robot_sequence` file; ``ValueError`` naming file (and line) for anything else."""
    path = Path(path)
    lines = [(no, line) for no, line in enumerate(read_text(path).splitlines(), start=1) if line.strip()]
    if not lines:
        raise ValueError(f"{path}: empty file")
    records = []
    for no, line in lines:
        try:
            records.append(json.loads(line))
        except (json.JSONDecodeError, RecursionError) as exc:
            raise ValueError(f"{path}:{no}: not JSON ({str(exc)[:80]})") from None
        if not isinstance(records[-1], dict):
            raise ValueError(f"{path}:{no}: expected a JSON object, got {type(records[-1]).__name__}")
    header, rows = records[0], records[1:]
    if header.get("format") != FORMAT or header.get("version") != VERSION:
        raise ValueError(f"{path}: not a {FORMAT} v{VERSION} file (header {str(header)[:80]})")
    try:
        config = RobotWorldConfig.from_dict(header["config"])
        T, N, M = len(rows), int(config.n_agents), int(config.max_detections)
    except (KeyError, TypeError, ValueError, AttributeError, OverflowError) as exc:
        raise ValueError(f"{path}:{lines[0][0]}: malformed header config ({str(exc)[:120]})") from None
    if not (0 <= N <= MAX_AGENTS and 0 <= M <= MAX_DETECTIONS):
        raise ValueError(f"{path}: n_agents={N} / max_detections={M} outside [0, {MAX_AGENTS}] / [0, {MAX_DETECTIONS}]")
    if T != header.get("n_frames"):
        raise ValueError(f"{path}: header says {header.get('n_frames')} frames, file has {T}")
    try:
        return _assemble(config, header, rows, T, N, M)
    except _RecordError as exc:
        no = lines[exc.index + 1][0]
        raise ValueError(f"{path}:{no}: malformed frame record ({str(exc.__cause__ or exc)[:120]})") from None
    except (KeyError, TypeError, IndexError, ValueError, AttributeError, OverflowError) as exc:
        raise ValueError(f"{path}: malformed frame record ({str(exc)[:120]})") from None


class _RecordError(ValueError):
    """A frame record that cannot be read; ``index``: its place among the records (0: the first frame)."""

    def __init__(self, index: int) -> None:
        super().__init__(f"frame record {index}")
        self.index = index


def _assemble(config: RobotWorldConfig, header: dict, rows: list[dict], T: int, N: int, M: int) -> RobotSequence:
    valid = np.zeros((T, M), dtype=bool)
    pos, head, score = np.zeros((T, M, 2)), np.zeros((T, M)), np.zeros((T, M))
    label = np.full((T, M), -1, dtype=int)
    b_parts: dict[str, list] = {"agent_id": [], "t_sent": [], "t_received": [], "heading": []}
    offsets = np.zeros(T + 1, dtype=int)
    truth: dict[str, list[Any]] = {k: [] for k in ("position", "heading", "visible", "occlusion", "field_position",
                                                   "observer", "n_false_positives", "n_misses")}
    time = np.zeros(T)
    for k, row in enumerate(rows):
        try:
            _read_record(k, row, N, M, time, valid, pos, head, score, label, b_parts, offsets, truth)
        except (KeyError, TypeError, IndexError, ValueError, AttributeError, OverflowError) as exc:
            raise _RecordError(k) from exc
    reports = ReportArrays(
        agent_id=np.asarray(b_parts["agent_id"], dtype=int), t_sent=np.asarray(b_parts["t_sent"], dtype=float),
        t_received=np.asarray(b_parts["t_received"], dtype=float), heading=np.asarray(b_parts["heading"], dtype=float),
        frame_offsets=offsets, n_sent=int(header["reports_sent"]),
    )
    arrays = RobotArrays(
        time=time, det_valid=valid, det_position=pos, det_heading=head, det_score=score, det_label=label,
        true_position=np.asarray(truth["position"], dtype=float).reshape(T, N, 2),
        true_heading=np.asarray(truth["heading"], dtype=float).reshape(T, N),
        visible=np.asarray(truth["visible"], dtype=bool).reshape(T, N),
        occlusion=np.asarray(truth["occlusion"], dtype=float).reshape(T, N),
        field_position=np.asarray(truth["field_position"], dtype=float).reshape(T, N, 2),
        observer=np.asarray(truth["observer"], dtype=float).reshape(T, 3), reports=reports,
        n_false_positives=np.asarray(truth["n_false_positives"], dtype=int),
        n_misses=np.asarray(truth["n_misses"], dtype=int),
    )
    return RobotSequence(config, int(header["seed"]), arrays)


def _read_record(k: int, row: dict, N: int, M: int, time: np.ndarray, valid: np.ndarray, pos: np.ndarray,
                 head: np.ndarray, score: np.ndarray, label: np.ndarray, b_parts: dict[str, list],
                 offsets: np.ndarray, truth: dict[str, list[Any]]) -> None:
    """Read frame record ``k`` into the arrays."""
    if row["frame"] != k:
        raise ValueError(f"frame records out of order: record {k} is frame {row['frame']}")
    time[k] = row["time"]
    if not np.isfinite(time[k]):
        raise ValueError(f"frame {k}: time must be a finite number of seconds, got {row['time']}")
    d = row["detections"]
    n = len(d["label"])
    if n > M:
        raise ValueError(f"frame {k}: {n} detections exceed max_detections {M}")
    valid[k, :n] = True
    if np.shape(d["position"]) != ((n, 2) if n else (0,)) or not len(d["heading"]) == len(d["score"]) == n:
        raise ValueError(f"frame {k}: {n} labels but position, heading and score of shapes {np.shape(d['position'])}, "
                         f"{np.shape(d['heading'])}, {np.shape(d['score'])} (expected ({n}, 2), ({n},), ({n},))")
    if n:
        labels = np.asarray(d["label"], dtype=float)
        if labels.shape != (n,) or not ((labels == np.floor(labels)) & (labels >= -1) & (labels < N)).all():
            raise ValueError(f"frame {k}: detection labels must be whole numbers from -1 (a false positive) to "
                             f"{N - 1}, got {d['label']}"[:160])
        pos[k, :n], head[k, :n], score[k, :n], label[k, :n] = d["position"], d["heading"], d["score"], labels
        if not all(np.isfinite(a[k, :n]).all() for a in (pos, head, score)):
            raise ValueError(f"frame {k}: NaN or infinity in a detection")
    b = row["beacons"]
    m = len(b["agent_id"])
    if any(len(b[key]) != m for key in b_parts):
        raise ValueError(f"frame {k}: the reports' agent_id, t_sent, t_received and heading differ in length")
    if m:
        ids = np.asarray(b["agent_id"], dtype=float)
        if not ((ids == np.floor(ids)) & (ids >= 0) & (ids < N)).all():
            raise ValueError(f"frame {k}: report agent ids must be whole numbers from 0 to {N - 1}, "
                             f"got {b['agent_id']}"[:160])
        if not np.isfinite(np.asarray([b["t_sent"], b["t_received"], b["heading"]], dtype=float)).all():
            raise ValueError(f"frame {k}: NaN or infinity in a report")
    for key, values in b_parts.items():
        values.extend(b[key])
    offsets[k + 1] = offsets[k] + m
    if not np.isfinite(np.asarray(row["truth"]["observer"], dtype=float)).all():
        raise ValueError(f"frame {k}: NaN or infinity in the observer's pose")
    for key, values in truth.items():
        values.append(row["truth"][key])
