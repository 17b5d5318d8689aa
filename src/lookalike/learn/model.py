"""The association network in PyTorch (training only; needs torch): stacked LSTM or GRU layers and one linear layer
whose ``M·(N+1)`` outputs are read as M softmax groups."""

from __future__ import annotations

import numpy as np

from lookalike._optional import needs
from lookalike.trackers.lstm.checkpoint import NetworkWeights
from lookalike.trackers.lstm.encoding import EncodingSpec

with needs("torch"):
    import torch
    from torch import nn

_NAMES = (("weight_ih", "w_ih"), ("weight_hh", "w_hh"), ("bias_ih", "b_ih"), ("bias_hh", "b_hh"))  # torch, ours


class AssociationNet(nn.Module):
    """``forward(x (b, t, n_inputs), state) -> (log-probabilities (b, t, M, N+1), state)``."""

    input_mean: torch.Tensor  # registered buffers
    input_std: torch.Tensor

    def __init__(self, spec: EncodingSpec, hidden: int = 64, num_layers: int = 5, cell: str = "lstm") -> None:
        super().__init__()
        if cell not in ("lstm", "gru"):
            raise ValueError(f"cell must be 'lstm' or 'gru', got {cell!r}")
        self.spec, self.hidden, self.cell = spec, hidden, cell
        rnn = nn.LSTM if cell == "lstm" else nn.GRU
        self.rnn = rnn(spec.n_inputs, hidden, num_layers=num_layers, batch_first=True)
        self.head = nn.Linear(hidden, spec.n_slots * spec.n_classes)
        self.register_buffer("input_mean", torch.zeros(spec.n_inputs, dtype=torch.float64))
        self.register_buffer("input_std", torch.ones(spec.n_inputs, dtype=torch.float64))

    def set_normalisation(self, mean: np.ndarray, std: np.ndarray) -> None:
        """Store input standardisation statistics (saved with the weights)."""
        self.input_mean.copy_(torch.as_tensor(mean, dtype=torch.float64))
        self.input_std.copy_(torch.as_tensor(np.maximum(std, 1e-6), dtype=torch.float64))

    def forward(self, x: torch.Tensor, state=None):
        z = ((x.double() - self.input_mean) / self.input_std).to(self.head.weight.dtype)
        out, state = self.rnn(z, state)
        logits = self.head(out)
        logits = logits.view(*logits.shape[:-1], self.spec.n_slots, self.spec.n_classes)
        return torch.log_softmax(logits, dim=-1), state

    def load_exported(self, weights: NetworkWeights) -> None:
        """Take the weights and normalisation of :meth:`export`'s output (same cell, sizes and input layout)."""
        mine = (self.spec, self.cell, self.hidden, self.rnn.num_layers)
        theirs = (weights.spec, weights.cell, weights.hidden, len(weights.layers))
        if mine != theirs:
            raise ValueError(f"weights of (spec, cell, hidden, layers) {theirs} do not fit this network {mine}")
        with torch.no_grad():
            for i, layer in enumerate(weights.layers):
                for name, key in _NAMES:
                    getattr(self.rnn, f"{name}_l{i}").copy_(torch.as_tensor(layer[key]))
            self.head.weight.copy_(torch.as_tensor(weights.head_weight))
            self.head.bias.copy_(torch.as_tensor(weights.head_bias))
        self.set_normalisation(weights.input_mean, weights.input_std)

    def export(self, info: dict | None = None) -> NetworkWeights:
        """The weights as numpy arrays for :class:`~lookalike.trackers.lstm.network.NumpyAssociationNet`."""
        def array(t: torch.Tensor) -> np.ndarray:
            return t.detach().cpu().double().numpy().copy()

        layers = [{key: array(getattr(self.rnn, f"{name}_l{i}")) for name, key in _NAMES}
                  for i in range(self.rnn.num_layers)]
        return NetworkWeights(
            spec=self.spec, cell=self.cell, hidden=self.hidden, layers=layers, head_weight=array(self.head.weight),
            head_bias=array(self.head.bias), input_mean=self.input_mean.cpu().numpy().copy(),
            input_std=self.input_std.cpu().numpy().copy(), info=dict(info or {}),
        )
