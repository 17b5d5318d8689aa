"""The trained association network evaluated with numpy only (no torch at inference)."""

from __future__ import annotations

import numpy as np

from lookalike.trackers.lstm.checkpoint import NetworkWeights


def _sigmoid(x: np.ndarray) -> np.ndarray:
    return 0.5 * (1.0 + np.tanh(0.5 * x))


class NumpyAssociationNet:
    """Step-by-step evaluation of the stacked recurrent network (its state kept until :meth:`reset`)."""

    def __init__(self, weights: NetworkWeights) -> None:
        self.weights = weights
        self.spec = weights.spec
        self._layers = [
            (
                layer["w_ih"].T.copy(),
                layer["w_hh"].T.copy(),
                layer["b_ih"] + (layer["b_hh"] if weights.cell == "lstm" else 0),
                layer["b_hh"],
            )
            for layer in weights.layers
        ]
        self._inv_std = 1.0 / weights.input_std
        self._head_w = weights.head_weight.T.copy()
        self.reset()

    def reset(self, batch: int | None = None) -> None:
        """Zero the recurrent state (for a batch of ``batch`` sequences, or a single one)."""
        shape = (self.weights.hidden,) if batch is None else (batch, self.weights.hidden)
        n = len(self._layers)
        self._h = [np.zeros(shape) for _ in range(n)]
        self._c = [np.zeros(shape) for _ in range(n)]

    def step(self, x: np.ndarray) -> np.ndarray:
        """Advance one frame of raw input ``(n_inputs,)`` (or a batch ``(b, n_inputs)``), standardised here; return
        class probabilities ``(M, N+1)`` (or ``(b, M, N+1)``)."""
        h_in = (np.asarray(x, dtype=float) - self.weights.input_mean) * self._inv_std
        hidden = self.weights.hidden
        for i, (w_ih, w_hh, b, b_hh) in enumerate(self._layers):
            h, c = self._h[i], self._c[i]
            if self.weights.cell == "lstm":
                gates = h_in @ w_ih + h @ w_hh + b
                ig = _sigmoid(gates[..., :hidden])
                fg = _sigmoid(gates[..., hidden : 2 * hidden])
                gg = np.tanh(gates[..., 2 * hidden : 3 * hidden])
                og = _sigmoid(gates[..., 3 * hidden :])
                c = fg * c + ig * gg
                h = og * np.tanh(c)
                self._c[i] = c
            else:  # GRU, PyTorch's formulation
                gi = h_in @ w_ih + b
                gh = h @ w_hh + b_hh
                r = _sigmoid(gi[..., :hidden] + gh[..., :hidden])
                z = _sigmoid(gi[..., hidden : 2 * hidden] + gh[..., hidden : 2 * hidden])
                n = np.tanh(gi[..., 2 * hidden :] + r * gh[..., 2 * hidden :])
                h = (1.0 - z) * n + z * h
            self._h[i] = h
            h_in = h
        logits = h_in @ self._head_w + self.weights.head_bias
        logits = logits.reshape(*logits.shape[:-1], self.spec.n_slots, self.spec.n_classes)
        logits = logits - logits.max(axis=-1, keepdims=True)
        p = np.exp(logits)
        probabilities: np.ndarray = p / p.sum(axis=-1, keepdims=True)
        return probabilities
