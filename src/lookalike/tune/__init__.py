"""Choosing a tracker's parameters on labelled data, and the left-out score of that choice (Optuna, the ``tune``
extra, for studies only)."""

from __future__ import annotations

from lookalike.tune.ablation import ParameterGain, one_at_a_time, parameter_gains
from lookalike.tune.data import load_tuning_data, score_params, sequence_key
from lookalike.tune.folds import Fold, k_folds, leave_one_group_out, make_folds
from lookalike.tune.objective import CRITERIA, criterion, evaluate_table, objective
from lookalike.tune.params_file import TunedParams, check_params, load_params, read_params, save_params
from lookalike.tune.selection import FoldChoice, combined_left_out, leave_one_out_selection, select_from_table
from lookalike.tune.space import DEFAULT_SPACES, Dim, default_space, sample, space_from_json, space_to_json
from lookalike.tune.study import SAMPLERS, StudyResult, run_study

__all__ = [
    "CRITERIA", "DEFAULT_SPACES", "Dim", "Fold", "FoldChoice", "ParameterGain", "SAMPLERS", "StudyResult",
    "TunedParams", "check_params", "combined_left_out", "criterion", "default_space", "evaluate_table",
    "k_folds", "leave_one_group_out", "leave_one_out_selection", "load_params", "load_tuning_data",
    "make_folds", "objective", "one_at_a_time", "parameter_gains", "read_params", "run_study", "sample",
    "save_params", "score_params", "select_from_table", "sequence_key", "space_from_json", "space_to_json",
]
