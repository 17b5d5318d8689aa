"""The labelling page: people label robot detections with identities in a browser (seed A's
human-performance tool), correct a tracker's labels, make ground truth, or measure their own
identification success rate ("human benchmark")."""

from lookalike.viz.label.exports import export_mot, export_truth, load_labels
from lookalike.viz.label.server import STATIC_DIR, LabelApp, make_server
from lookalike.viz.label.session import open_label_app
from lookalike.viz.label.store import UNSET, LabelStore, label_path_for, score_labels

__all__ = [
    "STATIC_DIR",
    "UNSET",
    "LabelApp",
    "LabelStore",
    "export_mot",
    "export_truth",
    "label_path_for",
    "load_labels",
    "make_server",
    "open_label_app",
    "score_labels",
]
