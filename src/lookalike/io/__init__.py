"""Reading and writing tracking data: MOTChallenge text files, sequence folders, streaming
input/output for the frame loop (:mod:`lookalike.io.stream`), and the results documents that every
``--json`` writes (:mod:`lookalike.io.results`, with its JSON schema)."""

from lookalike.io.motchallenge import (
    MotTable,
    frames_from_table,
    read_mot,
    tracks_to_rows,
    write_mot,
)
from lookalike.io.sequences import MotSequence, find_sequences, read_seqinfo
from lookalike.io.stream import DetectionStream, MotWriter

__all__ = [
    "DetectionStream",
    "MotSequence",
    "MotTable",
    "MotWriter",
    "find_sequences",
    "frames_from_table",
    "read_mot",
    "read_seqinfo",
    "tracks_to_rows",
    "write_mot",
]
