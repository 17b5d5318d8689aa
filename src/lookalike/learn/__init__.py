"""The LSTM association network of seed A: input encoding, numpy inference, checkpoints.

Torch is needed only for training (``lookalike.learn.model`` and ``lookalike.learn.training``);
everything imported here runs on numpy alone.
"""

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
