"""Recordings of the pixel pipeline: rendered robot sequences turned into labelled robot-sequence files.

Each sequence is simulated, rendered and perceived as ``lookalike bench pixels`` does
(:func:`lookalike.bench.pixels.perceive_sequence`, same seeds); the recording keeps the simulation's reports, times and
truth with the pixel detections, labelled with the robot whose rendered box they overlap best (IoU >= ``min_iou``, else
-1). Written as ``.labelled.jsonl`` files, they train and test the LSTM like a team's recordings."""

from __future__ import annotations

import dataclasses
from collections.abc import Iterator
from pathlib import Path

import numpy as np

from lookalike.bench.pixels import PerceivedSequence, perceive_sequence
from lookalike.bench.progress import ProgressFactory
from lookalike.eval import identification_success_rate
from lookalike.geometry.camera import Camera
from lookalike.io.robot_sequences import write_robot_sequence
from lookalike.sim import PRESET_NAMES, RobotSequence, preset, simulate_robots
from lookalike.trackers import make_tracker
from lookalike.trackers.parts.identity import labels_from_tracks
from lookalike.vision.pipeline import RobotPipeline
from lookalike.viz.robot_pixels import world_for_camera

SUFFIX = ".labelled.jsonl"


def recording_seeds(setup: str, sequences: int, seed: int) -> list[int]:
    """Seeds of the ``sequences`` recordings of preset ``setup`` from base ``seed`` (as ``bench pixels``)."""
    if setup not in PRESET_NAMES:
        raise ValueError(f"unknown preset {setup!r}; known: {', '.join(PRESET_NAMES)}")
    return [seed + 1000 * PRESET_NAMES.index(setup) + k for k in range(sequences)]


def to_recording(perceived: PerceivedSequence) -> RobotSequence:
    """The simulated sequence of ``perceived`` with its detections replaced by the pixel detections
    (most probable first, at most the world's M) and their renderer-truth labels."""
    seq = perceived.sequence
    a = seq.arrays
    T, M = a.det_valid.shape
    valid = np.zeros((T, M), dtype=bool)
    position, heading, score = np.zeros((T, M, 2)), np.zeros((T, M)), np.zeros((T, M))
    label = np.full((T, M), -1, dtype=int)
    for k, (det, truth) in enumerate(zip(perceived.detections, perceived.truth)):
        assert det.position is not None and det.heading is not None and det.score is not None
        n = min(len(det), M)
        valid[k, :n] = True
        position[k, :n], heading[k, :n], score[k, :n] = det.position[:n], det.heading[:n], det.score[:n]
        label[k, :n] = truth[:n]
    detected = np.zeros_like(a.visible)
    for k in range(T):
        ids = label[k][label[k] >= 0]
        detected[k, ids] = True
    arrays = dataclasses.replace(
        a, det_valid=valid, det_position=position, det_heading=heading, det_score=score, det_label=label,
        n_false_positives=((label == -1) & valid).sum(axis=1), n_misses=(a.visible & ~detected).sum(axis=1))
    return RobotSequence(seq.config, seq.seed, arrays)


def record_pixels(setup: str, sequences: int, frames: int, seed: int, pipe: RobotPipeline, camera: Camera,
                  min_iou: float = 0.3, progress: ProgressFactory | None = None) -> Iterator[RobotSequence]:
    """Pixel recordings of ``sequences`` sequences of ``frames`` frames of preset ``setup`` (see the module),
    one at a time as each is done."""
    cfg = world_for_camera(preset(setup), camera)
    advance = progress(f"{setup}: rendering + perception", sequences * frames) if progress else None
    for s in recording_seeds(setup, sequences, seed):
        yield to_recording(perceive_sequence(pipe, simulate_robots(cfg, frames, s), camera, min_iou,
                                             min_visible=0.5, advance=advance))


def write_recording(recording: RobotSequence, folder: str | Path, setup: str) -> Path:
    """Write ``recording`` as ``FOLDER/pixels-SETUP-SEED.labelled.jsonl``; the path written."""
    return write_robot_sequence(Path(folder) / f"pixels-{setup}-{recording.seed}{SUFFIX}", recording)


def identifier_labels(recordings: list[RobotSequence], name: str = "lstm", **params: object
                      ) -> tuple[list[np.ndarray], list[np.ndarray]]:
    """Per frame, the labels identifier ``name`` gives and the true labels, the identifier run over every
    recording from its first frame with its N and M from the recording; ``params`` go to ``make_tracker``."""
    predicted: list[np.ndarray] = []
    truth: list[np.ndarray] = []
    for rec in recordings:
        kwargs = {"n_agents": rec.config.n_agents, **params}
        if name.startswith("lstm") or name == "set":
            kwargs.setdefault("n_slots", rec.config.max_detections)
        tracker = make_tracker(name, **kwargs)
        for frame in rec.frames():
            predicted.append(labels_from_tracks(len(frame.detections), tracker.update(frame)))
        truth.extend(rec.true_labels())
    return predicted, truth


def score_identifier(recordings: list[RobotSequence], name: str = "lstm", **params: object) -> tuple[float, int]:
    """Identification success rate (a false positive labelled as such counts as correct, as in ``bench
    pixels``) and the number of detections of identifier ``name`` run over every recording from its
    first frame, with its N and M from the recording; ``params`` go to ``make_tracker`` (e.g. ``weights``)."""
    predicted, truth = identifier_labels(recordings, name, **params)
    return identification_success_rate(predicted, truth), sum(len(t) for t in truth)


__all__ = ["SUFFIX", "identifier_labels", "record_pixels", "recording_seeds", "score_identifier", "to_recording",
           "write_recording"]
