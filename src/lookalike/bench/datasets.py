"""The datasets of ``lookalike bench real`` as :class:`RealSequence`: MOT15 and pig boxes, HexBug blobs scored on head
points, and ``mot17-synth`` (``-synth2``/``-synth3``: other draws), MOT17 ground truth seen through
:func:`~lookalike.bench.synthetic.synthesize_detections`."""

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
    """The data folder: ``option``, else ``$LOOKALIKE_DATA``, else ``../shared/data`` (``FileNotFoundError``)."""
    if option is not None:
        path, why = Path(option), "--data"
    elif os.environ.get(DATA_ENV):
        path, why = Path(os.environ[DATA_ENV]), f"${DATA_ENV}"
    else:
        path, why = Path.cwd().parent / "shared" / "data", "../shared/data from the current directory"
    if path.is_dir():
        return path
    raise FileNotFoundError(f"data folder not found: tried {path} ({why}); give --data FOLDER or set ${DATA_ENV}")


@dataclass(frozen=True, eq=False)
class RealSequence:
    """One sequence: per frame (0-based) ``(n, 4)`` px boxes and ``(n,)`` scores; ground truth as boxes (``gt``) or
    points (``gt_points``: 1-based frame, id, ``(n, 2)`` px); ``image_size`` ``(width, height)`` px; ``n_targets``
    the documented count of a closed set; ``benchmark`` the ground-truth rules of scoring."""

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
                                image_size=seq.image_size, n_targets=PIGS_COUNT if dataset == "pigs" else None))
    if not out:
        raise ValueError(f"{root}: no sequence with det/det.txt and gt/gt.txt")
    return out


def cut_sequence(seq: RealSequence, part: str) -> RealSequence:
    """``seq`` whole (``"full"``), cut to frames ``1..⌊N/2⌋`` (``"first"``) or ``⌊N/2⌋+1..N`` (``"second"``,
    renumbered from 1), detections and ground truth alike."""
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
    """MOT17 ground truth under ``root`` with :func:`synthesize_detections` seeded by ``seed`` and name."""
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
    """Whether points ``(n, 2)`` px were stored as (y, x): more fall outside the image read as (x, y) than as
    (y, x) (a tie, or no image size: no)."""
    if image_size is None or not len(xy):
        return False
    width, height = image_size

    def outside(x: np.ndarray, y: np.ndarray) -> int:
        return int(((x < 0) | (x >= width) | (y < 0) | (y >= height)).sum())

    return outside(xy[:, 1], xy[:, 0]) < outside(xy[:, 0], xy[:, 1])


def read_hexbug_points(path: Path, image_size: tuple[int, int] | None = None
                       ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(frame 1-based (n,), id (n,), xy (n, 2) px)`` from a HexBug CSV (``,t,hexbug,x,y``; (y, x) detected)."""
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
    """One HexBug clip through the blob detector with the settings ``lookalike track --detector blob`` estimates,
    with its head points; ``cache``: a folder, ``True`` for the default one, ``False`` for none."""
    from lookalike.io.video_frames import source_frames
    from lookalike.pipeline.blob_detections import auto_blob_config, cached_blob_detections

    config, _ = auto_blob_config(video, [], cache=cache)
    found = cached_blob_detections(video, config, cache=cache)
    rows, length = found.rows, found.frames
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
    """The sequences of datasets ``names`` under ``root``; ``sequences``: only these names (a dataset's name: all of
    it); ``max_clips``: at most this many HexBug clips, detected on the chosen backend."""
    out: list[RealSequence] = []
    known: list[str] = []  # every sequence name of the datasets, to name a selection that matches none
    for name in names:
        if name not in DATASETS:
            raise ValueError(f"datasets: unknown dataset {name!r}; known: {', '.join(DATASETS)}")
        folder = root / "mot17" / "gt" if name in SYNTH_SEEDS else root / name
        if not folder.is_dir():
            raise FileNotFoundError(f"{folder}: dataset folder not found (set --data)")
        if name == "hexbug":
            every = hexbug_clips(folder)
            known += [c.stem for c in every]
            clips = [c for c in every if not sequences or c.stem in sequences][:max_clips]
            with JobPool(min(workers, max(len(clips), 1)), backend, address) as pool:
                out += pool.map(detect_hexbug, clips)
            continue
        seqs = load_mot17_synth(folder, SYNTH_SEEDS[name], name) if name in SYNTH_SEEDS else load_boxes(folder, name)
        known += [q.name for q in seqs]
        out += _selected(seqs, name, sequences)
    if not out:
        unknown = [q for q in sequences or () if q not in known and q not in names]
        raise ValueError(f"no sequence selected: {', '.join(map(repr, unknown))} not in {', '.join(names)}; known: "
                         f"{', '.join(known)}" if unknown else "no sequence selected")
    return out


__all__ = ["DATASETS", "DATA_ENV", "HEXBUG_FPS", "PARTS", "PIGS_COUNT", "SYNTH_SEEDS", "RealSequence",
           "cut_sequence", "detect_hexbug", "hexbug_clips", "load_boxes", "load_datasets", "load_mot17_synth",
           "points_swapped", "read_hexbug_points", "resolve_data_root", "synthesize_detections"]
