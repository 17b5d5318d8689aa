"""The set associator in numpy (``lookalike.learn.set_model.SetAssociator``'s maths for one sequence, any N agents and
K detections per frame, no padding), its input tokens and weight files (``.npz`` + ``.json``)."""

from __future__ import annotations

import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from lookalike.trackers.kernels.world import einsum
from lookalike.trackers.parts.weights_io import CheckpointError, read_arrays, read_metadata, write_weights

FORMAT = "lookalike-set-associator"
FORMAT_VERSION = 1
POSITION_SCALE_M = 4.0
OFFSET_SCALE_M = 2.0
AGENT_FEATURES = 4
DET_FEATURES = 5
MAX_AGE_S = 5.0  # report age at which an agent token's age feature saturates, seconds
SHIPPED_SET_WEIGHTS = Path(__file__).with_name("weights") / "set_any.npz"


def shipped_set_weights_path() -> Path:
    """The shipped set-associator weights (one file for every N and M)."""
    if not SHIPPED_SET_WEIGHTS.is_file():
        raise CheckpointError(f"{SHIPPED_SET_WEIGHTS}: the shipped set-associator weights are missing; "
                              "train some with `lookalike train --model set` and pass weights=PATH")
    return SHIPPED_SET_WEIGHTS


def agent_tokens(heading_rad: np.ndarray, age_s: np.ndarray, max_age_s: float = MAX_AGE_S) -> np.ndarray:
    """Agent tokens ``(..., N, 4)`` from latest headings and report ages ``(..., N)`` (NaN: never heard)."""
    heading = np.asarray(heading_rad, dtype=float)
    age = np.asarray(age_s, dtype=float)
    known = np.isfinite(heading) & np.isfinite(age)
    h = np.where(known, heading, 0.0)
    out = np.empty((*known.shape, AGENT_FEATURES))
    out[..., 0] = np.where(known, np.cos(h), 0.0)
    out[..., 1] = np.where(known, np.sin(h), 0.0)
    out[..., 2] = np.where(known, np.minimum(np.maximum(age, 0.0), max_age_s) / max_age_s, 1.0)
    out[..., 3] = known
    return out


def detection_tokens(position_m: np.ndarray, heading_rad: np.ndarray, probability: np.ndarray) -> np.ndarray:
    """Detection tokens ``(..., K, 5)``: ``x, y`` (metres), ``cos φ, sin φ``, ``γ``."""
    phi = np.asarray(heading_rad, dtype=float)
    pos = np.asarray(position_m, dtype=float)
    return np.concatenate([pos, np.cos(phi)[..., None], np.sin(phi)[..., None],
                           np.asarray(probability, dtype=float)[..., None]], axis=-1)


@dataclass(frozen=True)
class SetWeights:
    """Parameters by PyTorch name, the widths ``token, pair, memory`` and free-form ``info``."""

    arrays: dict[str, np.ndarray]
    token: int
    pair: int
    memory: int
    max_age_s: float = 5.0
    info: dict[str, Any] = field(default_factory=dict)

    def shapes(self) -> dict[str, tuple[int, ...]]:
        """Expected shape of every array."""
        d, f, h = self.token, self.pair, self.memory
        return {
            "det.weight": (d, 5), "det.bias": (d,), "agent.weight": (d, 6 + h), "agent.bias": (d,),
            "pair_d.weight": (f, d), "pair_a.weight": (f, d), "pair_q.weight": (f, 6), "pair_q.bias": (f,),
            "pair2.weight": (f, f), "pair2.bias": (f,), "score.weight": (1, f), "score.bias": (1,),
            "fp1.weight": (f, d + f), "fp1.bias": (f,), "fp2.weight": (1, f), "fp2.bias": (1,),
            "gru.weight_ih": (3 * h, f + 5), "gru.weight_hh": (3 * h, h), "gru.bias_ih": (3 * h,),
            "gru.bias_hh": (3 * h,),
        }


def save_set_weights(weights: SetWeights, path: str | os.PathLike[str]) -> Path:
    """Write ``path`` (``.npz``) and its ``.json`` configuration; returns the ``.npz`` path."""
    path = Path(path).with_suffix(".npz")
    path.parent.mkdir(parents=True, exist_ok=True)
    payload: dict[str, Any] = {k: np.asarray(v, dtype=np.float32) for k, v in weights.arrays.items()}
    meta = {"format": FORMAT, "format_version": FORMAT_VERSION, "token": weights.token, "pair": weights.pair,
            "memory": weights.memory, "max_age_s": weights.max_age_s, "info": weights.info}
    write_weights(path, payload, meta, compressed=True)
    return path


def load_set_weights(path: str | os.PathLike[str]) -> SetWeights:
    """Load weights written by :func:`save_set_weights`; :class:`CheckpointError` naming the file
    when the metadata is missing, of another format or version, or an array has the wrong shape."""
    path, meta_path, meta = read_metadata(path, FORMAT, "lookalike set associator")
    if meta.get("format_version") != FORMAT_VERSION:
        raise CheckpointError(f"{meta_path}: format_version {meta.get('format_version')} is not supported "
                              f"(this lookalike reads {FORMAT_VERSION})")
    loaded = read_arrays(path, meta_path, meta)
    try:
        arrays = {k: v.astype(np.float64) for k, v in loaded.items()}
    except (TypeError, ValueError) as exc:
        raise CheckpointError(f"{path}: cannot read the weights ({exc})") from None
    try:
        weights = SetWeights(arrays, int(meta["token"]), int(meta["pair"]), int(meta["memory"]),
                             float(meta.get("max_age_s", 5.0)), dict(meta.get("info", {})))
    except KeyError as exc:
        raise CheckpointError(f"{meta_path}: missing field {exc}") from None
    for name, shape in weights.shapes().items():
        got = np.shape(arrays[name]) if name in arrays else ()
        if got != shape:
            raise CheckpointError(f"{path}: {name} has shape {got}, expected {shape}")
        if not np.isfinite(arrays[name]).all():
            raise CheckpointError(f"{path}: {name} holds NaN or infinity")
    return weights


def _relu_(x: np.ndarray) -> np.ndarray:
    """``max(x, 0)`` in place (``x`` a new array); ``x``."""
    np.maximum(x, 0.0, out=x)
    return x


def _sigmoid_(x: np.ndarray) -> np.ndarray:
    """``0.5 (1 + tanh(x / 2))`` in place (``x`` a new array); ``x``."""
    x *= 0.5
    np.tanh(x, out=x)
    x += 1.0
    x *= 0.5
    return x


class NumpySetAssociator:
    """Frame-by-frame evaluation: :meth:`reset` for N agents, then :meth:`step` per frame."""

    def __init__(self, weights: SetWeights) -> None:
        self.weights = weights
        w = weights.arrays
        t = {k: np.ascontiguousarray(v.T) for k, v in w.items() if v.ndim == 2}
        self._t, self._b = t, w
        h = weights.memory
        self._gru_b = w["gru.bias_ih"].copy()
        self._gru_b[: 2 * h] += w["gru.bias_hh"][: 2 * h]
        self._gru_bn = w["gru.bias_hh"][2 * h :].copy()
        self._scale = np.array([1 / POSITION_SCALE_M, 1 / POSITION_SCALE_M, 1.0, 1.0, 1.0])
        self.reset(1)

    def reset(self, n_agents: int) -> None:
        """Forget everything; the next frames have ``n_agents`` agents."""
        if n_agents < 1:
            raise ValueError(f"n_agents must be >= 1, got {n_agents}")
        self.n_agents = n_agents
        self.h = np.zeros((n_agents, self.weights.memory))
        self.p = np.zeros((n_agents, 2))
        self.m = np.zeros((n_agents, 1))
        self.s = np.zeros((n_agents, 1))

    def forget(self, agents: np.ndarray) -> None:
        """Forget the memory of the agents ``agents`` (indices or a boolean mask), as if never seen."""
        for state in (self.h, self.p, self.m, self.s):
            state[agents] = 0.0

    def swap(self, a: int, b: int) -> None:
        """Exchange the memories (state, remembered position, weight, staleness) of agents ``a`` and ``b``."""
        for state in (self.h, self.p, self.m, self.s):
            state[[a, b]] = state[[b, a]]

    def remembers(self, threshold: float = 0.5) -> np.ndarray:
        """``(N,)`` whether each agent's remembered position (``p``, metres) is held with weight above
        ``threshold`` (0 after :meth:`reset` or :meth:`forget`, towards 1 as detections are attended)."""
        return self.m[:, 0] > threshold

    def step(self, agents: np.ndarray, dets: np.ndarray, dt_s: float) -> np.ndarray:
        """Advance each agent's memory, remembered position and staleness by one frame (agent tokens ``(N, 4)``,
        detection tokens ``(K, 5)``); return class probabilities ``(K, N+1)`` (agents, then false positive)."""
        t, b = self._t, self._b
        agents = np.asarray(agents, dtype=float)
        dets = np.asarray(dets, dtype=float).reshape(-1, 5)
        n = self.n_agents
        if agents.shape != (n, 4):
            raise ValueError(f"agents must have shape ({n}, 4), got {agents.shape}")
        u = _relu_((dets * self._scale) @ t["det.weight"] + b["det.bias"])
        a = _relu_(np.concatenate([agents, self.m, np.log1p(self.s), self.h], axis=1) @ t["agent.weight"]
                   + b["agent.bias"])
        c_phi, s_phi = dets[:, 2:3], dets[:, 3:4]
        c_psi, s_psi = agents[:, 0], agents[:, 1]
        mj = self.m[:, 0]
        off = dets[:, None, :2] - self.p[None]
        sq = off * off
        k = len(dets)
        q = np.empty((k, n, 6))  # (pair features: heading agreement, offset, distance, weight)
        q[..., 0] = c_phi * c_psi + s_phi * s_psi
        q[..., 1] = s_phi * c_psi - c_phi * s_psi
        q[..., 2:4] = off * self.m / OFFSET_SCALE_M
        q[..., 4] = np.sqrt(sq[..., 0] + sq[..., 1] + 1e-6) * mj / OFFSET_SCALE_M
        q[..., 5] = mj
        e = (u @ t["pair_d.weight"])[:, None] + (a @ t["pair_a.weight"])[None]
        e += q @ t["pair_q.weight"]
        e += b["pair_q.bias"]
        e2 = _relu_(e) @ t["pair2.weight"]
        e2 += b["pair2.bias"]
        e2 = _relu_(e2)  # (K,N,F)
        score = (e2 @ t["score.weight"])[..., 0] + b["score.bias"][0]
        if k:
            fp_in = np.concatenate([u, np.maximum.reduce(e2, axis=1)], axis=1)
            fp = _relu_(fp_in @ t["fp1.weight"] + b["fp1.bias"]) @ t["fp2.weight"] + b["fp2.bias"]
        else:
            fp = np.zeros((0, 1))
        logits = np.concatenate([score, fp], axis=1)
        if k:
            logits -= np.maximum.reduce(logits, axis=1, keepdims=True)
        prob = np.exp(logits, out=logits)
        prob /= np.maximum(np.add.reduce(prob, axis=1, keepdims=True), 1e-300)
        w = prob[:, :n]  # (K,N)
        total = np.add.reduce(w, axis=0)[:, None]
        g = np.minimum(total, 1.0)
        mean_pos = (w.T @ dets[:, :2]) / (total + 1e-6)
        self.p = self.p + g * (mean_pos - self.p)
        self.m = self.m + g * (1.0 - self.m)
        self.s = (1.0 - g) * (self.s + dt_s)
        msg = einsum("kn,knf->nf", w, e2)
        x = np.concatenate([msg, g, agents], axis=1)
        hd = self.weights.memory
        gi = x @ t["gru.weight_ih"] + self._gru_b
        gh = self.h @ t["gru.weight_hh"]
        rz = _sigmoid_(gi[:, : 2 * hd] + gh[:, : 2 * hd])
        r, z = rz[:, :hd], rz[:, hd:]
        cand = gh[:, 2 * hd :] + self._gru_bn
        cand *= r
        cand += gi[:, 2 * hd :]
        np.tanh(cand, out=cand)
        cand *= 1.0 - z
        cand += z * self.h
        self.h = cand
        return np.asarray(prob)
