"""The LSTM association network of the robot-identification paper: input encoding, numpy inference, checkpoints. Torch
is needed only for training (``model``, ``training``)."""

from lookalike.learn.checkpoint import CheckpointError, NetworkWeights, load_weights, save_weights
from lookalike.learn.encoding import EncodingSpec, encode_frame
from lookalike.learn.numpy_net import NumpyAssociationNet

__all__ = [
    "CheckpointError",
    "EncodingSpec",
    "NetworkWeights",
    "NumpyAssociationNet",
    "encode_frame",
    "load_weights",
    "save_weights",
]
