"""Scoring a simulated team: the node's published labels, and the same tracker run offline on the sequence."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from lookalike.eval import identification_success_rate
from lookalike.node.messages import TeamState
from lookalike.sim.robots import RobotSequence
from lookalike.trackers.parts.identity import labels_from_tracks


def online_identification(sequence: RobotSequence, teams: Sequence[TeamState]) -> tuple[float, int]:
    """Identification success rate of the team states' labels against the truth, over the frames
    that have a team state, and how many frames that is."""
    truth = sequence.true_labels()
    by_frame = {t.frame: t for t in teams if 0 <= t.frame < len(truth) and len(t.labels) == len(truth[t.frame])}
    frames = sorted(by_frame)
    rate = identification_success_rate([np.asarray(by_frame[k].labels, dtype=int) for k in frames],
                                       [truth[k] for k in frames])
    return rate, len(frames)


def offline_identification(sequence: RobotSequence, tracker: object) -> float:
    """Identification success rate of ``tracker`` run directly on ``sequence`` (the same labelling
    rule as the node: ``labels_from_tracks``)."""
    predicted = []
    for frame in sequence.frames():
        snapshots = tracker.update(frame)  # type: ignore[attr-defined]
        predicted.append(labels_from_tracks(len(frame.detections), snapshots))
    return identification_success_rate(predicted, sequence.true_labels())
