"""The real datasets of ``lookalike bench real``: MOT15 and pig boxes, HexBug blobs and head points,
and ``mot17-synth``: the real MOT17 ground truth seen through a *synthetic* detector (labelled so).

Every sequence becomes a :class:`RealSequence` holding the detections every tracker receives
(identical for all of them) and the ground truth it is scored against. Box data (MOT15, pigs) is
scored with CLEAR/identity/HOTA on boxes (IoU 0.5, MOT15 rules; MOT17 rules for ``mot17-synth``);
HexBug clips are scored on points: the centre of each reported box against the annotated head
position within ``radius`` pixels.

``mot17-synth`` is a set that no parameter of lookalike was chosen on: the 7 MOT17 training
sequences' real trajectories (``mot17/gt``) with detections from the noise model of
:func:`lookalike.sim.boxes.simulate_boxes`, scaled to the box size (:func:`synthesize_detections`,
fixed seeds). Its detections are not a real detector's; use it for rankings, not absolute figures.
``mot17-synth2`` and ``mot17-synth3`` are the same with other seeds (:data:`SYNTH_SEEDS`): unseen by decisions
made on ``mot17-synth`` (``mot17-synth2`` was scored once after issue #10's self-calibration, ``mot17-synth3``
after its matching priority).
"""

from __future__ import annotations

import csv
import zlib
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

from lookalike.io import MotTable, find_sequences, read_mot

DATASETS = ("mot15", "pigs", "hexbug", "mot17-synth", "mot17-synth2", "mot17-synth3")
# The synthetic MOT17 sets and the seed of their detections: ``mot17-synth2`` and ``mot17-synth3`` are the same
# ground truth seen with other noise draws, kept for checks after anything was decided with ``mot17-synth`` in view.
SYNTH_SEEDS = {"mot17-synth": 0, "mot17-synth2": 1, "mot17-synth3": 2}
PARTS = ("full", "first", "second")  # whole sequences, frames 1..⌊N/2⌋, frames ⌊N/2⌋+1..N
PIGS_COUNT = 23  # the pigs folder documents 23 animals (../shared/data/README.md), not read from gt
HEXBUG_FPS = 10.0
# Clips whose CSV has x and y swapped (listed in ../shared/data/README.md).
HEXBUG_SWAPPED_XY = frozenset({"training020", "training058", "training076", "training078", "training079",
                               "training082", "training083", "training089"})


@dataclass(frozen=True, eq=False)
class RealSequence:
    """One sequence: per-frame detections (0-based frames) and its ground truth.

    Attributes:
        dataset: ``"mot15"``, ``"pigs"`` or ``"hexbug"``.
        name: sequence or clip name.
        frame_rate: frames per second.
        length: number of frames.
        det_xywh: per frame, ``(n, 4)`` boxes in pixels.
        det_score: per frame, ``(n,)`` detector scores.
        gt: ground-truth boxes (:class:`MotTable`) for box data, else None.
        gt_points: ``(frame (n,) 1-based, id (n,), xy (n, 2) px)`` for point data, else None.
        image_size: ``(width, height)`` in pixels, or None.
        n_targets: the documented number of targets when the set is closed, else None.
        benchmark: the ground-truth rules of :func:`lookalike.eval.evaluate_sequence`.
    """

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
    """``seq`` whole (``"full"``), cut to frames ``1..⌊N/2⌋`` (``"first"``, where parameters are
    chosen) or to frames ``⌊N/2⌋+1..N`` (``"second"``, unseen by that choice, renumbered from 1).

    Detections and ground truth (boxes or points) are cut alike; a tracker starts afresh on a part.
    """
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


def synthesize_detections(gt: MotTable, length: int, image_size: tuple[int, int], rng: np.random.Generator, *,
                          noise: float = 0.05, miss_rate: float = 0.1, min_visibility: float = 0.25,
                          false_positives_per_frame: float = 0.5) -> tuple[list[np.ndarray], list[np.ndarray]]:
    """Per-frame detections ``(n, 4)`` px and scores ``(n,)`` of a synthetic detector looking at MOT17
    ground truth ``gt`` (columns: consider flag, class, visibility).

    The noise model of :func:`lookalike.sim.boxes.simulate_boxes`, with its noise proportional to the
    box: a considered pedestrian (class 1) at least ``min_visibility`` visible is missed with
    probability ``miss_rate``, else seen with Gaussian noise of std ``noise``·[w, h, w/2, h/2] on
    ``[x, y, w, h]`` and a score uniform in [0.6, 1]; each frame adds Poisson(``false_positives_per_frame``)
    false boxes, uniform over the image (``(width, height)`` px) with the size of a random true box,
    scored uniform in [0.3, 0.8].
    """
    if gt.extra.shape[1] < 2:
        raise ValueError("gt: expected MOT17 ground truth with class and visibility columns")
    person = (gt.conf != 0) & (gt.extra[:, 0] == 1)
    visible = person & (gt.extra[:, 1] >= min_visibility)
    sizes = gt.xywh[person, 2:4]
    if not len(sizes):
        raise ValueError("gt: no considered pedestrian boxes")
    width, height = image_size
    xywh, score = [], []
    for k in range(1, length + 1):
        truth = gt.xywh[visible & (gt.frame == k)]
        seen = truth[rng.random(len(truth)) >= miss_rate]
        scale = np.column_stack([seen[:, 2], seen[:, 3], seen[:, 2] / 2, seen[:, 3] / 2])
        boxes = seen + rng.normal(0.0, 1.0, seen.shape) * noise * scale
        n_fp = rng.poisson(false_positives_per_frame)
        fp_size = sizes[rng.integers(0, len(sizes), n_fp)]
        fp = np.column_stack([rng.uniform(0, 1, (n_fp, 2)) * np.maximum([width, height] - fp_size, 1.0), fp_size])
        boxes = np.vstack([boxes, fp])
        boxes[:, 2:] = np.maximum(np.abs(boxes[:, 2:]), 1.0)
        conf = np.concatenate([rng.uniform(0.6, 1.0, len(seen)), rng.uniform(0.3, 0.8, n_fp)])
        order = rng.permutation(len(boxes))
        xywh.append(boxes[order])
        score.append(conf[order])
    return xywh, score


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


def read_hexbug_points(path: Path) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(frame 1-based (n,), id (n,), xy (n, 2) px)`` from a HexBug CSV (``,t,hexbug,x,y``)."""
    rows = []
    with open(path, newline="") as fh:
        for rec in csv.DictReader(fh):
            try:
                rows.append((float(rec["t"]), float(rec["hexbug"]), float(rec["x"]), float(rec["y"])))
            except (KeyError, TypeError, ValueError):
                raise ValueError(f"{path}: expected columns t, hexbug, x, y with numbers") from None
    arr = np.array(rows, dtype=float).reshape(-1, 4)
    arr = arr[np.isfinite(arr).all(axis=1)]
    xy = arr[:, 2:4][:, ::-1] if path.stem in HEXBUG_SWAPPED_XY else arr[:, 2:4]
    return arr[:, 0].astype(int) + 1, arr[:, 1].astype(int), np.ascontiguousarray(xy)


def hexbug_clips(root: Path) -> list[Path]:
    """The HexBug videos that have an annotation CSV next to them."""
    return [v for v in sorted(root.glob("*.mp4")) if v.with_suffix(".csv").is_file()]


def detect_hexbug(video: Path) -> RealSequence:
    """Run the blob detector over one HexBug clip (OpenCV needed) and attach its head points.

    Detector settings are those of ``benchmarks/hexbug_blobs.py`` (median background, threshold 30
    grey levels, blobs of at least 800 px², opening 9 px, stabilised), chosen on the video alone.
    """
    from lookalike.vision.blob import BlobConfig, BlobDetector, read_video

    frames = read_video(str(video))
    detector = BlobDetector(BlobConfig(threshold=30.0, min_area_px=800.0, open_px=9, stabilise=True)).fit(frames)
    dets = [detector(image) for image in frames]
    height, width = frames[0].shape[:2]
    return RealSequence("hexbug", video.stem, HEXBUG_FPS, len(frames), [d.xywh for d in dets],
                        [d.score for d in dets], gt_points=read_hexbug_points(video.with_suffix(".csv")),
                        image_size=(width, height))
