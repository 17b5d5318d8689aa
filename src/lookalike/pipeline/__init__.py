"""What ``lookalike track`` runs, as a library: detections read or found, trackers fed, results written; the
command line only parses options and prints."""

from lookalike.pipeline.request import TrackRequest
from lookalike.pipeline.runner import Event, RunResult, run

__all__ = ["Event", "RunResult", "TrackRequest", "run"]
