"""The set associator in PyTorch (training only; needs torch): one permutation-equivariant network for every team
size; per frame an MLP scores detection-agent pairs, a softmax over "agent 1..N or false positive" gives the output,
and each agent's memory (position, GRU state) attends to the detections. :mod:`lookalike.trackers.set.network`
evaluates the same maths with numpy."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from lookalike._optional import needs
from lookalike.trackers.set.network import AGENT_FEATURES, DET_FEATURES

with needs("torch"):
    import torch
    from torch import nn

PAIR_FEATURES = 6
POSITION_SCALE_M = 4.0  # positions are divided by this before entering the network
OFFSET_SCALE_M = 2.0  # pair offsets likewise


@dataclass(frozen=True)
class SetSizes:
    """Widths of the set associator: detection/agent tokens ``token``, pair MLP ``pair``, agent memory ``memory``."""

    token: int = 32
    pair: int = 64
    memory: int = 48


class SetAssociator(nn.Module):
    """``forward(agents (B,T,N,4), dets (B,T,M,5), valid (B,T,M), dt_s, state) -> (log-probs (B,T,M,N+1), state)``."""

    def __init__(self, sizes: SetSizes = SetSizes()) -> None:
        super().__init__()
        d, f, h = sizes.token, sizes.pair, sizes.memory
        self.sizes = sizes
        self.det = nn.Linear(DET_FEATURES, d)
        self.agent = nn.Linear(AGENT_FEATURES + 2 + h, d)
        self.pair_d = nn.Linear(d, f, bias=False)
        self.pair_a = nn.Linear(d, f, bias=False)
        self.pair_q = nn.Linear(PAIR_FEATURES, f)
        self.pair2 = nn.Linear(f, f)
        self.score = nn.Linear(f, 1)
        self.fp1 = nn.Linear(d + f, f)
        self.fp2 = nn.Linear(f, 1)
        self.gru = nn.GRUCell(f + 1 + AGENT_FEATURES, h)

    def initial_state(self, batch: int, n_agents: int, like: torch.Tensor) -> tuple[torch.Tensor, ...]:
        """Memory ``h (B,N,H)``, position ``p (B,N,2)`` metres, known ``m (B,N,1)``, staleness ``s (B,N,1)`` s."""
        z = like.new_zeros
        b, n = batch, n_agents
        return z(b, n, self.sizes.memory), z(b, n, 2), z(b, n, 1), z(b, n, 1)

    def precompute(self, agents: torch.Tensor, dets: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor]:
        """The parts that do not depend on the memory, for any leading shape: detection tokens
        ``u (..., M, D)`` and pre-activations of every pair ``(..., M, N, F)`` from the detection
        token and the heading agreement (pair bias included)."""
        scale = dets.new_tensor([1 / POSITION_SCALE_M, 1 / POSITION_SCALE_M, 1.0, 1.0, 1.0])
        u = torch.relu(self.det(dets * scale))
        c_phi, s_phi = dets[..., 2, None], dets[..., 3, None]  # (...,M,1)
        c_psi, s_psi = agents[..., 0].unsqueeze(-2), agents[..., 1].unsqueeze(-2)  # (...,1,N)
        heading = torch.stack([c_phi * c_psi + s_phi * s_psi, s_phi * c_psi - c_phi * s_psi], dim=-1)
        pre = (self.pair_d(u).unsqueeze(-2) + nn.functional.linear(heading, self.pair_q.weight[:, :2])
               + self.pair_q.bias)
        return u, pre

    def step(self, agents: torch.Tensor, dets: torch.Tensor, valid: torch.Tensor, dt_s: float,
             state: tuple[torch.Tensor, ...], pre: tuple[torch.Tensor, torch.Tensor] | None = None,
             ) -> tuple[torch.Tensor, tuple[torch.Tensor, ...]]:
        """One frame: ``agents (B,N,4)``, ``dets (B,M,5)``, ``valid (B,M)`` -> log-probs ``(B,M,N+1)``."""
        h, p, m, s = state
        B, N, _ = agents.shape
        u, pair_pre = pre if pre is not None else self.precompute(agents, dets)
        a = torch.relu(self.agent(torch.cat([agents, m, torch.log1p(s), h], dim=-1)))
        mj = m[..., 0][:, None]  # (B,1,N)
        off = dets[:, :, None, :2] - p[:, None]  # (B,M,N,2)
        dist = torch.sqrt((off * off).sum(-1) + 1e-6)
        q = torch.stack([off[..., 0] * mj / OFFSET_SCALE_M, off[..., 1] * mj / OFFSET_SCALE_M,
                         dist * mj / OFFSET_SCALE_M, mj.expand_as(dist)], dim=-1)
        e = torch.relu(pair_pre + self.pair_a(a)[:, None] + nn.functional.linear(q, self.pair_q.weight[:, 2:]))
        e2 = torch.relu(self.pair2(e))  # (B,M,N,F)
        score = self.score(e2)[..., 0]  # (B,M,N)
        fp = self.fp2(torch.relu(self.fp1(torch.cat([u, e2.amax(dim=2)], dim=-1))))  # (B,M,1)
        logp = torch.log_softmax(torch.cat([score, fp], dim=-1), dim=-1)
        w = logp[..., :N].exp() * valid[..., None].to(logp.dtype)  # (B,M,N)
        total = w.sum(1)[..., None]  # (B,N,1)
        g = total.clamp(max=1.0)
        mean_pos = torch.einsum("bmn,bmc->bnc", w, dets[..., :2]) / (total + 1e-6)
        p = p + g * (mean_pos - p)
        m = m + g * (1.0 - m)
        s = (1.0 - g) * (s + dt_s)
        msg = torch.einsum("bmn,bmnf->bnf", w, e2)
        h = self.gru(torch.cat([msg, g, agents], dim=-1).reshape(B * N, -1), h.reshape(B * N, -1)).reshape(B, N, -1)
        return logp, (h, p, m, s)

    def forward(self, agents: torch.Tensor, dets: torch.Tensor, valid: torch.Tensor, dt_s: float,
                state: tuple[torch.Tensor, ...] | None = None) -> tuple[torch.Tensor, tuple[torch.Tensor, ...]]:
        B, T, N, _ = agents.shape
        if state is None:
            state = self.initial_state(B, N, agents)
        u, pre = self.precompute(agents, dets)
        out = []
        frames = zip(agents.unbind(1), dets.unbind(1), valid.unbind(1), u.unbind(1), pre.unbind(1))
        for a_t, d_t, v_t, u_t, pre_t in frames:  # unbind: one gradient buffer, not one per frame
            logp, state = self.step(a_t, d_t, v_t, dt_s, state, (u_t, pre_t))
            out.append(logp)
        return torch.stack(out, dim=1), state

    def export(self) -> dict[str, np.ndarray]:
        """The parameters as float64 numpy arrays, by PyTorch name (for :mod:`lookalike.trackers.set.network`)."""
        return {k: v.detach().cpu().double().numpy().copy() for k, v in self.state_dict().items()}

    def load_exported(self, arrays: dict[str, np.ndarray]) -> None:
        """Take parameters from :meth:`export`'s output (same sizes)."""
        self.load_state_dict({k: torch.as_tensor(v, dtype=torch.float32) for k, v in arrays.items()})
