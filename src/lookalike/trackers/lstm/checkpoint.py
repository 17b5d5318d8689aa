"""Exported network weights: a ``.npz`` of arrays plus a JSON metadata file beside it.

``model.npz`` holds ``layer{i}.w_ih``, ``layer{i}.w_hh``, ``layer{i}.b_ih``, ``layer{i}.b_hh`` (PyTorch's gate order:
LSTM ``i, f, g, o``; GRU ``r, z, n``), ``head.weight``, ``head.bias``, ``input_mean``, ``input_std`` and
``save_id``. ``model.json`` records the format version, cell type, sizes, the encoding version, free-form training
information and the ``save_id`` of its ``.npz`` (a pair whose ``save_id`` differs is refused)."""

from __future__ import annotations

import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from lookalike.trackers.lstm.encoding import ENCODING_VERSION, EncodingSpec
from lookalike.trackers.parts.weights_io import CheckpointError, read_arrays, read_metadata, write_weights

FORMAT_VERSION = 1
GATES = {"lstm": 4, "gru": 3}


@dataclass(frozen=True, eq=False)
class NetworkWeights:
    """Weights and metadata of a trained association network."""

    spec: EncodingSpec
    cell: str
    hidden: int
    layers: list[dict[str, np.ndarray]]
    head_weight: np.ndarray
    head_bias: np.ndarray
    input_mean: np.ndarray
    input_std: np.ndarray
    info: dict[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        w = self
        if w.cell not in GATES:
            raise CheckpointError(f"weights: unknown cell type {w.cell!r} (expected 'lstm' or 'gru')")
        g, h, n_in = GATES[w.cell], w.hidden, w.spec.n_inputs
        expected_out = w.spec.n_slots * w.spec.n_classes
        for i, layer in enumerate(w.layers):
            width = n_in if i == 0 else h
            shapes = {"w_ih": (g * h, width), "w_hh": (g * h, h), "b_ih": (g * h,), "b_hh": (g * h,)}
            for name, shape in shapes.items():
                arr = layer.get(name)
                if arr is None:
                    raise CheckpointError(f"weights: layer{i}.{name} is missing")
                if np.shape(arr) != shape:
                    raise CheckpointError(f"weights: layer{i}.{name} has shape {np.shape(arr)}, expected {shape}")
                if not np.isfinite(arr).all():
                    raise CheckpointError(f"weights: layer{i}.{name} holds NaN or infinity")
        checks = {"head.weight": (w.head_weight, (expected_out, h)), "head.bias": (w.head_bias, (expected_out,)),
                  "input_mean": (w.input_mean, (n_in,)), "input_std": (w.input_std, (n_in,))}
        for name, (arr, shape) in checks.items():
            if np.shape(arr) != shape:
                raise CheckpointError(f"weights: {name} has shape {np.shape(arr)}, expected {shape}")
            if not np.isfinite(arr).all():
                raise CheckpointError(f"weights: {name} holds NaN or infinity")
        if (w.input_std <= 0).any():
            raise CheckpointError("weights: input_std must be positive")


def save_weights(weights: NetworkWeights, path: str | os.PathLike[str]) -> Path:
    """Write ``path`` (``.npz``) and its ``.json`` metadata; returns the ``.npz`` path."""
    path = Path(path).with_suffix(".npz")
    path.parent.mkdir(parents=True, exist_ok=True)
    arrays = {"head.weight": weights.head_weight, "head.bias": weights.head_bias,
              "input_mean": weights.input_mean, "input_std": weights.input_std}
    for i, layer in enumerate(weights.layers):
        for name, arr in layer.items():
            arrays[f"layer{i}.{name}"] = arr
    payload: dict[str, Any] = {k: np.asarray(v, dtype=np.float64) for k, v in arrays.items()}
    spec = weights.spec
    meta = {"format": "lookalike-association-net", "format_version": FORMAT_VERSION,
            "encoding_version": ENCODING_VERSION, "cell": weights.cell, "hidden": weights.hidden,
            "num_layers": len(weights.layers), "n_agents": spec.n_agents, "n_slots": spec.n_slots,
            "max_age_s": spec.max_age_s, "relative_headings": spec.relative_headings, "info": weights.info}
    if spec.protocol != "ours":  # files of the default layout stay as they were
        meta["protocol"] = spec.protocol
    write_weights(path, payload, meta)
    return path


def load_weights(path: str | os.PathLike[str], n_agents: int | None = None,
                 n_slots: int | None = None) -> NetworkWeights:
    """Load weights saved by :func:`save_weights`, refusing files that do not fit.

    Raises :class:`CheckpointError` naming the file when the metadata is missing or of another version, when N or M
    differ from the requested ``n_agents``/``n_slots``, or when an array has the wrong shape."""
    path, meta_path, meta = read_metadata(path, "lookalike-association-net", "lookalike association network")
    for key, current in (("format_version", FORMAT_VERSION), ("encoding_version", ENCODING_VERSION)):
        if meta.get(key) != current:
            raise CheckpointError(f"{meta_path}: {key} {meta.get(key)} is not supported "
                                  f"(this lookalike reads {current})")
    for key, wanted in (("n_agents", n_agents), ("n_slots", n_slots)):
        if wanted is not None and meta.get(key) != wanted:
            raise CheckpointError(f"{meta_path}: trained for {key}={meta.get(key)}, but {wanted} was requested")
    arrays = read_arrays(path, meta_path, meta)
    get: Any = arrays.get  # (None where missing: the shape check rejects it)
    try:
        spec = EncodingSpec(int(meta["n_agents"]), int(meta["n_slots"]), float(meta["max_age_s"]),
                            bool(meta.get("relative_headings", False)), str(meta.get("protocol", "ours")))
        layers = [{name: get(f"layer{i}.{name}") for name in ("w_ih", "w_hh", "b_ih", "b_hh")}
                  for i in range(int(meta["num_layers"]))]
        return NetworkWeights(spec, str(meta["cell"]), int(meta["hidden"]), layers, get("head.weight"),
                              get("head.bias"), get("input_mean"), get("input_std"), dict(meta.get("info", {})))
    except KeyError as exc:
        raise CheckpointError(f"{meta_path}: missing field {exc}") from None
    except CheckpointError as exc:
        raise CheckpointError(f"{path}: {exc}") from None
