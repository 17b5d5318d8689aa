"""Reading and writing tracking data: MOTChallenge text files and sequence folders."""

from lookalike.io.motchallenge import (
    MotTable,
    frames_from_table,
    read_mot,
    tracks_to_rows,
    write_mot,
)
from lookalike.io.sequences import MotSequence, find_sequences, read_seqinfo

__all__ = [
    "MotSequence",
    "MotTable",
    "find_sequences",
    "frames_from_table",
    "read_mot",
    "read_seqinfo",
    "tracks_to_rows",
    "write_mot",
]
