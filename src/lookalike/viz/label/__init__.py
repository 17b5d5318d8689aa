"""The labelling page: people label robot detections with identities in a browser, to correct a tracker's labels, make
ground truth, or measure their own identification success rate ("human benchmark")."""

from lookalike.viz.label.exports import export_mot, export_truth, load_labels
from lookalike.viz.label.human import HumanResult, human_result_path, read_human_results, write_human_result
from lookalike.viz.label.server import STATIC_DIR, LabelApp, make_server
from lookalike.viz.label.session import open_label_app
from lookalike.viz.label.store import UNSET, LabelStore, label_path_for, score_labels

__all__ = [
    "STATIC_DIR",
    "UNSET",
    "HumanResult",
    "LabelApp",
    "LabelStore",
    "export_mot",
    "export_truth",
    "human_result_path",
    "label_path_for",
    "load_labels",
    "make_server",
    "open_label_app",
    "read_human_results",
    "score_labels",
    "write_human_result",
]
