"""The real datasets of ``lookalike bench real``: MOT15 and pig boxes, HexBug blobs and head points, and
``mot17-synth``: the real MOT17 ground truth seen through a synthetic detector (labelled so).

Each sequence becomes a :class:`RealSequence` (the detections every tracker receives, and the ground truth). Boxes are
scored with CLEAR/identity/HOTA (IoU 0.5, MOT15 rules; MOT17 rules for ``mot17-synth``), HexBug clips on points (box
centres against annotated heads). ``mot17-synth`` (and ``-synth2``/``-synth3``, other noise draws: :data:`SYNTH_SEEDS`)
uses :func:`~lookalike.bench.synthetic.synthesize_detections`; no parameter was chosen on it, and its figures are for
rankings, not absolutes. The data folder: :func:`resolve_data_root` (``--data``, ``LOOKALIKE_DATA``, else
``../shared/data``)."""

from __future__ import annotations

import csv
import os
import zlib
from collections.abc import Iterator, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

from lookalike.bench.synthetic import synthesize_detections
from lookalike.io import MotTable, find_sequences, read_mot
from lookalike.parallel import JobPool
from lookalike.types import Detections, Frame

DATASETS = ("mot15", "pigs", "hexbug", "mot17-synth", "mot17-synth2", "mot17-synth3")
# The synthetic MOT17 sets and the seed of their detections.
SYNTH_SEEDS = {"mot17-synth": 0, "mot17-synth2": 1, "mot17-synth3": 2}
PARTS = ("full", "first", "second")  # whole sequences, frames 1..⌊N/2⌋, frames ⌊N/2⌋+1..N
PIGS_COUNT = 23  # the pigs folder documents 23 animals (../shared/data/README.md), not read from gt
HEXBUG_FPS = 10.0
DATA_ENV = "LOOKALIKE_DATA"


def resolve_data_root(option: Path | str | None = None) -> Path:
    """The data folder: ``option`` when given, else ``$LOOKALIKE_DATA``, else ``../shared/data``
    relative to the current directory. Raises ``FileNotFoundError`` naming what was tried."""
    if option is not None:
        tried = [(Path(option), "--data")]
    elif os.environ.get(DATA_ENV):
        tried = [(Path(os.environ[DATA_ENV]), f"${DATA_ENV}")]
    else:
        tried = [(Path.cwd().parent / "shared" / "data", "../shared/data from the current directory")]
    for path, _ in tried:
        if path.is_dir():
            return path
    what = "; ".join(f"{p} ({why})" for p, why in tried)
    raise FileNotFoundError(f"data folder not found: tried {what}; give --data FOLDER or set ${DATA_ENV}")


@dataclass(frozen=True, eq=False)
class RealSequence:
    """One sequence: per-frame detections (0-based frames) and its ground truth.

    Attributes:
        dataset: ``"mot15"``, ``"pigs"``, ``"hexbug"`` or a ``mot17-synth`` set.
        name: sequence or clip name.
        frame_rate: frames per second.
        length: number of frames.
        det_xywh: per frame, ``(n, 4)`` boxes in pixels.
        det_score: per frame, ``(n,)`` detector scores.
        gt: ground-truth boxes (:class:`MotTable`) for box data, else None.
        gt_points: ``(frame (n,) 1-based, id (n,), xy (n, 2) px)`` for point data, else None.
        image_size: ``(width, height)`` in pixels, or None.
        n_targets: the documented number of targets when the set is closed, else None.
        benchmark: the ground-truth rules of :func:`lookalike.eval.evaluate_sequence`."""

    dataset: str
    name: str
    frame_rate: float
    length: int
    det_xywh: list[np.ndarray] = field(repr=False)
    det_score: list[np.ndarray] = field(repr=False)
    gt: MotTable | None = field(default=None, repr=False)
    gt_points: tuple[np.ndarray, np.ndarray, np.ndarray] | None = field(default=None, repr=False)
    image_size: tuple[int, int] | None = None
    n_targets: int | None = None
    benchmark: str = "MOT15"

    def frames(self) -> Iterator[Frame]:
        """The detections as :class:`Frame` objects, ``index`` 0-based, ``time = index / frame_rate``."""
        for k in range(self.length):
            dets = Detections(xywh=self.det_xywh[k], score=self.det_score[k])
            yield Frame(index=k, time=k / self.frame_rate, detections=dets)


def _split_frames(table: MotTable, length: int) -> tuple[list[np.ndarray], list[np.ndarray]]:
    order = np.argsort(table.frame, kind="stable")
    frames = table.frame[order]
    bounds = np.searchsorted(frames, np.arange(1, length + 2))
    xywh, conf = table.xywh[order], table.conf[order]
    return ([xywh[bounds[k]:bounds[k + 1]] for k in range(length)],
            [conf[bounds[k]:bounds[k + 1]] for k in range(length)])


def load_boxes(root: Path, dataset: str) -> list[RealSequence]:
    """MOTChallenge-style sequences under ``root`` (each with ``det/det.txt`` and ``gt/gt.txt``)."""
    out = []
    for seq in find_sequences(root):
        if seq.det_path is None or seq.gt_path is None:
            continue
        det, gt = read_mot(seq.det_path), read_mot(seq.gt_path)
        length = seq.length or int(max(det.frame.max(initial=0), gt.frame.max(initial=0)))
        xywh, score = _split_frames(det, length)
        out.append(RealSequence(dataset, seq.name, seq.frame_rate, length, xywh, score, gt=gt,
                                image_size=seq.image_size,
                                n_targets=PIGS_COUNT if dataset == "pigs" else None))
    if not out:
        raise ValueError(f"{root}: no sequence with det/det.txt and gt/gt.txt")
    return out


def cut_sequence(seq: RealSequence, part: str) -> RealSequence:
    """``seq`` whole (``"full"``), cut to frames ``1..⌊N/2⌋`` (``"first"``, where parameters are chosen) or to frames
    ``⌊N/2⌋+1..N`` (``"second"``, unseen by that choice, renumbered from 1).

    Detections and ground truth (boxes or points) are cut alike; a tracker starts afresh on a part."""
    if part not in PARTS:
        raise ValueError(f"part: expected one of {PARTS}, got {part!r}")
    if part == "full":
        return seq
    n = seq.length // 2
    lo, hi, shift = (0, n, 0) if part == "first" else (n, seq.length, n)
    gt, points = seq.gt, seq.gt_points
    if gt is not None:
        keep = (gt.frame > lo) & (gt.frame <= hi)
        gt = MotTable(gt.frame[keep] - shift, gt.track_id[keep], gt.xywh[keep], gt.conf[keep], gt.extra[keep])
    if points is not None:
        frame, ids, xy = points
        keep = (frame > lo) & (frame <= hi)
        points = (frame[keep] - shift, ids[keep], xy[keep])
    return replace(seq, name=f"{seq.name}[{part}]", length=hi - lo, det_xywh=seq.det_xywh[lo:hi],
                   det_score=seq.det_score[lo:hi], gt=gt, gt_points=points)


def load_mot17_synth(root: Path, seed: int = 0, dataset: str = "mot17-synth") -> list[RealSequence]:
    """The MOT17 ground-truth sequences under ``root`` (``mot17/gt``) with :func:`synthesize_detections`
    (seeded by ``seed`` and the sequence's name, so every run sees the same detections), labelled ``dataset``."""
    out = []
    for seq in find_sequences(root):
        if seq.gt_path is None:
            continue
        gt = read_mot(seq.gt_path)
        length = seq.length or int(gt.frame.max(initial=0))
        size = seq.image_size or (1920, 1080)
        rng = np.random.default_rng([seed, zlib.crc32(seq.name.encode())])
        xywh, score = synthesize_detections(gt, length, size, rng)
        out.append(RealSequence(dataset, seq.name, seq.frame_rate, length, xywh, score, gt=gt,
                                image_size=size, benchmark="MOT17"))
    if not out:
        raise ValueError(f"{root}: no sequence with gt/gt.txt")
    return out


def points_swapped(xy: np.ndarray, image_size: tuple[int, int] | None) -> bool:
    """Whether points ``(n, 2)`` px were stored as (y, x): more of them fall outside the image
    (``(width, height)`` px) read as (x, y) than read as (y, x). A tie (e.g. all inside both ways,
    or no image size) keeps the order as written."""
    if image_size is None or not len(xy):
        return False
    width, height = image_size

    def outside(x: np.ndarray, y: np.ndarray) -> int:
        return int(((x < 0) | (x >= width) | (y < 0) | (y >= height)).sum())

    return outside(xy[:, 1], xy[:, 0]) < outside(xy[:, 0], xy[:, 1])


def read_hexbug_points(path: Path, image_size: tuple[int, int] | None = None
                       ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(frame 1-based (n,), id (n,), xy (n, 2) px)`` from a HexBug CSV (``,t,hexbug,x,y``).

    Some CSVs store (y, x); with the clip's ``image_size`` (``(width, height)`` px) the order is decided by
    :func:`points_swapped` (points outside the image as (x, y) but inside as (y, x))."""
    rows = []
    with open(path, newline="") as fh:
        for rec in csv.DictReader(fh):
            try:
                rows.append((float(rec["t"]), float(rec["hexbug"]), float(rec["x"]), float(rec["y"])))
            except (KeyError, TypeError, ValueError):
                raise ValueError(f"{path}: expected columns t, hexbug, x, y with numbers") from None
    arr = np.array(rows, dtype=float).reshape(-1, 4)
    arr = arr[np.isfinite(arr).all(axis=1)]
    xy = arr[:, 2:4][:, ::-1] if points_swapped(arr[:, 2:4], image_size) else arr[:, 2:4]
    return arr[:, 0].astype(int) + 1, arr[:, 1].astype(int), np.ascontiguousarray(xy)


def hexbug_clips(root: Path) -> list[Path]:
    """The HexBug videos that have an annotation CSV next to them."""
    return [v for v in sorted(root.glob("*.mp4")) if v.with_suffix(".csv").is_file()]


def detect_hexbug(video: Path, cache: Path | bool = True) -> RealSequence:
    """Run the blob detector over one HexBug clip (OpenCV needed) and attach its head points.

    The detector settings are those ``lookalike track --video V --detector blob`` uses: estimated from the clip itself
    (:func:`lookalike.viz.blob_video.auto_blob_config`, no target count), nothing chosen for the bench. Detections are
    cached on disk (:func:`~lookalike.viz.blob_video.cached_blob_detection_rows`; ``cache``: a folder, ``True`` for the
    default one, ``False`` for none)."""
    from lookalike.viz.blob_video import auto_blob_config, cached_blob_detection_rows
    from lookalike.viz.overlay import source_frames

    config, _ = auto_blob_config(video, [], cache=cache)
    rows, length = cached_blob_detection_rows(video, config, cache=cache)
    frames, _, fps = source_frames(video)
    height, width = next(iter(frames)).shape[:2]
    points = read_hexbug_points(video.with_suffix(".csv"), (width, height))
    xywh, score = _split_frames(MotTable.from_rows(rows), length)
    return RealSequence("hexbug", video.stem, float(fps) if fps and fps > 0 else HEXBUG_FPS, length, xywh, score,
                        gt_points=points, image_size=(width, height))


def _selected(seqs: list[RealSequence], dataset: str, sequences: Sequence[str] | None) -> list[RealSequence]:
    return [s for s in seqs if not sequences or s.name in sequences or dataset in sequences]


def load_datasets(root: Path, names: Sequence[str], *, sequences: Sequence[str] | None = None,
                  max_clips: int | None = None, workers: int = 1, backend: str = "local",
                  address: str | None = None) -> list[RealSequence]:
    """The sequences of datasets ``names`` under ``root`` (HexBug detection runs on the chosen backend).

    ``sequences``: only these sequence/clip names (a dataset's name selects all of it); ``max_clips``: at most this many
    HexBug clips."""
    out: list[RealSequence] = []
    for name in names:
        if name not in DATASETS:
            raise ValueError(f"datasets: unknown dataset {name!r}; known: {', '.join(DATASETS)}")
        folder = root / "mot17" / "gt" if name in SYNTH_SEEDS else root / name
        if not folder.is_dir():
            raise FileNotFoundError(f"{folder}: dataset folder not found (set --data)")
        if name in SYNTH_SEEDS:
            out += _selected(load_mot17_synth(folder, SYNTH_SEEDS[name], name), name, sequences)
        elif name == "hexbug":
            clips = [c for c in hexbug_clips(folder) if not sequences or c.stem in sequences][:max_clips]
            with JobPool(min(workers, max(len(clips), 1)), backend, address) as pool:
                out += pool.map(detect_hexbug, clips)
        else:
            out += _selected(load_boxes(folder, name), name, sequences)
    if not out:
        raise ValueError("no sequence selected")
    return out


__all__ = ["DATASETS", "DATA_ENV", "HEXBUG_FPS", "PARTS", "PIGS_COUNT", "SYNTH_SEEDS", "RealSequence",
           "cut_sequence", "detect_hexbug", "hexbug_clips", "load_boxes", "load_datasets", "load_mot17_synth",
           "points_swapped", "read_hexbug_points", "resolve_data_root", "synthesize_detections"]
