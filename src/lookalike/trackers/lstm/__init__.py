"""The LSTM identifier of the robot-identification paper at inference: input encoding, numpy network, weight
files and the shipped weights. Training (torch) lives in :mod:`lookalike.learn`."""

from lookalike.trackers.lstm.checkpoint import NetworkWeights, load_weights, save_weights
from lookalike.trackers.lstm.encoding import EncodingSpec, encode_frame
from lookalike.trackers.lstm.network import NumpyAssociationNet
from lookalike.trackers.parts.weights_io import CheckpointError

__all__ = [
    "CheckpointError",
    "EncodingSpec",
    "NetworkWeights",
    "NumpyAssociationNet",
    "encode_frame",
    "load_weights",
    "save_weights",
]
