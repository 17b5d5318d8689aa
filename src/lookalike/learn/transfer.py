"""Warm start across set-ups: weights trained for (N, M) mapped onto a network for (N', M')."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

from lookalike.trackers.lstm.checkpoint import NetworkWeights
from lookalike.trackers.lstm.encoding import EncodingSpec
from lookalike.trackers.parts.weights_io import CheckpointError


def _input_map(source: EncodingSpec, target: EncodingSpec) -> np.ndarray:
    """For each input column of ``target``, the source column it copies, and whether it repeats one."""
    cols: list[int] = []
    aw, sw = target.agent_width, target.slot_width
    for j in range(target.n_agents):
        src = j % source.n_agents
        cols.extend(src * aw + c for c in range(aw))
    offset_s = source.agent_width * source.n_agents
    for k in range(target.n_slots):
        src = k % source.n_slots
        cols.extend(offset_s + src * sw + c for c in range(sw))
    return np.asarray(cols, dtype=np.int64)


def _repeat_mask_inputs(source: EncodingSpec, target: EncodingSpec) -> np.ndarray:
    agents = np.repeat(np.arange(target.n_agents) >= source.n_agents, target.agent_width)
    slots = np.repeat(np.arange(target.n_slots) >= source.n_slots, target.slot_width)
    return np.concatenate([agents, slots])


def _head_map(source: EncodingSpec, target: EncodingSpec) -> tuple[np.ndarray, np.ndarray]:
    rows, repeat = [], []
    for k in range(target.n_slots):
        ks = k % source.n_slots
        for c in range(target.n_classes):
            cs = source.n_agents if c == target.n_agents else c % source.n_agents
            rows.append(ks * source.n_classes + cs)
            repeat.append(k >= source.n_slots or (c != target.n_agents and c >= source.n_agents))
    return np.asarray(rows, dtype=np.int64), np.asarray(repeat, dtype=bool)


def transfer_weights(weights: NetworkWeights, target: EncodingSpec, mean: np.ndarray, std: np.ndarray,
                     rng: np.random.Generator, jitter: float = 0.1, info: dict | None = None) -> NetworkWeights:
    """``weights`` mapped onto ``target``'s set-up: upper layers copied; first-layer input columns and output head
    mapped block by block (agent ``j`` from ``j mod N``, slot ``k`` from ``k mod M``), repeated blocks jittered by
    ``jitter`` × the block's spread. ``mean``/``std`` ``(target.n_inputs,)``: the new input normalisation."""
    source = weights.spec
    if source.protocol != target.protocol:
        raise CheckpointError(f"cannot transfer weights of protocol {source.protocol!r} to {target.protocol!r}")
    if source.relative_headings != target.relative_headings:
        raise CheckpointError("cannot transfer weights between encodings with and without relative headings")
    if np.shape(mean) != (target.n_inputs,) or np.shape(std) != (target.n_inputs,):
        raise ValueError(f"mean and std must have shape ({target.n_inputs},)")

    def noisy(block: np.ndarray, repeat: np.ndarray, axis: int) -> np.ndarray:
        out = block.copy()
        scale = jitter * float(np.std(block)) if block.size else 0.0
        index: list[Any] = [slice(None)] * out.ndim
        index[axis] = np.flatnonzero(repeat)
        sub = out[tuple(index)]
        out[tuple(index)] = sub + rng.normal(0.0, scale, size=sub.shape)
        return out

    first = dict(weights.layers[0])
    w_ih = np.asarray(first["w_ih"])[:, _input_map(source, target)]
    first["w_ih"] = noisy(w_ih, _repeat_mask_inputs(source, target), axis=1)
    layers = [first] + [dict(layer) for layer in weights.layers[1:]]
    rows, repeat = _head_map(source, target)
    head_weight = noisy(np.asarray(weights.head_weight)[rows], repeat, axis=0)
    head_bias = np.asarray(weights.head_bias)[rows].copy()
    meta = dict(info or {})
    meta.setdefault("transferred_from", {"n_agents": source.n_agents, "n_slots": source.n_slots})
    return NetworkWeights(
        spec=target, cell=weights.cell, hidden=weights.hidden, layers=layers, head_weight=head_weight,
        head_bias=head_bias, input_mean=np.asarray(mean, dtype=float),
        input_std=np.maximum(np.asarray(std, dtype=float), 1e-6), info=meta,
    )


def transfer_from_file(path: str, target: EncodingSpec,
                       sample: Callable[[int, int, Any], tuple[np.ndarray, np.ndarray]], seeds: list[int], length: int,
                       seed: int = 0) -> NetworkWeights:
    """Weights at ``path`` onto ``target``, normalised by ``sample`` inputs over ``seeds``."""
    from lookalike.trackers.lstm.checkpoint import load_weights

    source = load_weights(path)
    xs = np.concatenate([sample(int(s), length, None)[0] for s in seeds])
    if xs.shape[1] != target.n_inputs:
        raise ValueError(f"the sampler gives {xs.shape[1]} inputs, the target encoding {target.n_inputs}")
    return transfer_weights(source, target, xs.mean(0), xs.std(0), np.random.default_rng(seed),
                            info={"transferred_from": {"path": str(path), "n_agents": source.spec.n_agents,
                                                       "n_slots": source.spec.n_slots}})
