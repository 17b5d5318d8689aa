"""Pixel recordings: sequences perceived as ``bench pixels`` does, with the pixel detections and their renderer-truth
labels in place of the simulator's, written as ``.labelled.jsonl`` robot sequences."""

from __future__ import annotations

import dataclasses
from collections.abc import Iterator
from pathlib import Path

import numpy as np

from lookalike.bench.ident import sequence_seeds
from lookalike.bench.pixels import PerceivedSequence, perceive_sequence
from lookalike.bench.progress import ProgressFactory
from lookalike.eval import identification_success_rate
from lookalike.geometry.camera import Camera
from lookalike.io.robot_sequences import write_robot_sequence
from lookalike.sim import RobotSequence, preset, simulate_robots
from lookalike.sim.robot_camera import world_for_camera
from lookalike.trackers import make_tracker
from lookalike.trackers.parts.identity import labels_from_tracks
from lookalike.vision.pipeline import RobotPipeline

SUFFIX = ".labelled.jsonl"


def recording_seeds(setup: str, sequences: int, seed: int) -> list[int]:
    """Seeds of the ``sequences`` recordings of team ``setup`` from base ``seed`` (as ``bench pixels``)."""
    return sequence_seeds([setup], sequences, seed)


def to_recording(perceived: PerceivedSequence) -> RobotSequence:
    """``perceived``'s sequence with the pixel detections (at most M) and their labels as its detections."""
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
    """Pixel recordings of ``sequences`` sequences of ``frames`` frames of preset ``setup``, as each is done."""
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
    """Per frame, identifier ``name``'s labels and the true ones over every recording."""
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
    """Success rate and detection count of :func:`identifier_labels`."""
    predicted, truth = identifier_labels(recordings, name, **params)
    return identification_success_rate(predicted, truth), sum(len(t) for t in truth)


__all__ = ["SUFFIX", "identifier_labels", "record_pixels", "recording_seeds", "score_identifier", "to_recording",
           "write_recording"]
