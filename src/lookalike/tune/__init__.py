"""Choosing a tracker's parameters on labelled data, and saying honestly how well that carries over.

- :mod:`lookalike.tune.space`: search spaces (declared for ``sort`` and ``boxtrack``, built from the
  defaults for other trackers, overridable by JSON),
- :mod:`lookalike.tune.study`: an Optuna study (TPE or random search) over sequences, parallel
  locally or on Ray, saved and resumable (``lookalike tune``),
- :mod:`lookalike.tune.folds` and :mod:`lookalike.tune.selection`: leave-one-sequence/dataset-out
  and K folds; the left-out score of the whole selection procedure,
- :mod:`lookalike.tune.ablation`: the left-out gain of tuning each parameter against fixing it,
- :mod:`lookalike.tune.params_file`: the parameter file that ``track --params`` and
  ``bench real --params`` read (:func:`load_params`),
- :mod:`lookalike.tune.data`: labelled data (bench datasets by name, MOTChallenge folders).

Optuna is needed for studies only (``pip install 'lookalike[tune]'``); parameter files, spaces,
folds and table selection work without it.
"""

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
