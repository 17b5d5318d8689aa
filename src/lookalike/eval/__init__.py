"""Evaluation: CLEAR MOT, identity and HOTA (TrackEval's definitions, values as fractions), and the robot-identification
paper's metrics (identification success rate, localisation error). :mod:`lookalike.eval.folders` scores folders of
results (``lookalike eval``)."""

from lookalike.eval.api import METRICS, combine, evaluate_data, evaluate_points, evaluate_sequence
from lookalike.eval.data import SequenceData
from lookalike.eval.identification import (
    identification_by_agent,
    identification_counts,
    identification_success_rate,
    localisation_coverage,
    localisation_error,
    localisation_error_by_agent,
    robot_success_rate,
)
from lookalike.eval.prepare import BENCHMARKS, prepare_boxes, prepare_points
from lookalike.eval.selection import headline, leave_one_out
from lookalike.eval.similarity import box_iou, point_similarity

__all__ = [
    "BENCHMARKS",
    "METRICS",
    "SequenceData",
    "box_iou",
    "combine",
    "evaluate_data",
    "evaluate_points",
    "evaluate_sequence",
    "headline",
    "identification_by_agent",
    "identification_counts",
    "identification_success_rate",
    "leave_one_out",
    "localisation_coverage",
    "localisation_error",
    "localisation_error_by_agent",
    "point_similarity",
    "prepare_boxes",
    "prepare_points",
    "robot_success_rate",
]
