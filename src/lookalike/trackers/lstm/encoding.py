"""Input encoding of one frame for the association network. Ours (``3·N + 5·M``): per agent ``cos ψ_j, sin ψ_j, age_j``
(latest report, its age in seconds clipped to ``max_age_s``; ``(0, 0, max_age_s)`` if never heard), then per slot ``x,
y, cos φ, sin φ, γ`` (metres, visual heading, detector probability), with ``relative_headings`` followed by ``cos(φ −
ψ_j), sin(φ − ψ_j)`` per agent. The paper's (``protocol="paper"``, ``N + 4·M``): ``ψ_j / π``; per slot ``x, y, φ / π,
γ``."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from lookalike.types import Detections

ENCODING_VERSION = 1
AGENT_WIDTH = 3
SLOT_WIDTH = 5
PAPER_AGENT_WIDTH = 1
PAPER_SLOT_WIDTH = 4
PROTOCOLS = ("ours", "paper")


@dataclass(frozen=True)
class EncodingSpec:
    """Sizes of the encoding: ``n_agents`` (N) reporting agents, ``n_slots`` (M) detection slots;
    ``protocol`` ``"ours"`` (default) or ``"paper"`` (the paper's ``N + 4·M`` inputs)."""

    n_agents: int
    n_slots: int
    max_age_s: float = 5.0
    relative_headings: bool = False
    protocol: str = "ours"

    def __post_init__(self) -> None:
        if self.n_agents < 1 or self.n_slots < 1:
            raise ValueError(f"n_agents and n_slots must be >= 1, got {self.n_agents}, {self.n_slots}")
        if self.protocol not in PROTOCOLS:
            raise ValueError(f"protocol must be one of {', '.join(PROTOCOLS)}, got {self.protocol!r}")
        if self.protocol == "paper" and self.relative_headings:
            raise ValueError("the paper protocol has no relative headings")

    @property
    def n_inputs(self) -> int:
        """Length of one frame's input vector."""
        return self.agent_width * self.n_agents + self.slot_width * self.n_slots

    @property
    def agent_width(self) -> int:
        """Inputs per agent."""
        return PAPER_AGENT_WIDTH if self.protocol == "paper" else AGENT_WIDTH

    @property
    def slot_width(self) -> int:
        """Inputs per detection slot."""
        if self.protocol == "paper":
            return PAPER_SLOT_WIDTH
        return SLOT_WIDTH + (2 * self.n_agents if self.relative_headings else 0)

    @property
    def n_classes(self) -> int:
        """Classes per slot: agents 0..N-1, then the false-positive class N."""
        return self.n_agents + 1


def encode_agents(spec: EncodingSpec, heading_rad: np.ndarray, age_s: np.ndarray) -> np.ndarray:
    """Agent blocks ``(..., 3·N)`` from latest headings and report ages ``(..., N)`` (NaN = never heard)."""
    heading = np.asarray(heading_rad, dtype=float)
    age = np.asarray(age_s, dtype=float)
    known = np.isfinite(heading) & np.isfinite(age)
    h = np.where(known, heading, 0.0)
    out = np.stack([np.where(known, np.cos(h), 0.0), np.where(known, np.sin(h), 0.0),
                    np.where(known, np.clip(age, 0.0, spec.max_age_s), spec.max_age_s)], axis=-1)
    return out.reshape(*heading.shape[:-1], AGENT_WIDTH * spec.n_agents)


def encode_slots(spec: EncodingSpec, position_m: np.ndarray, heading_rad: np.ndarray, probability: np.ndarray,
                 agent_heading_rad: np.ndarray | None = None) -> np.ndarray:
    """Slot blocks ``(slot_width·M,)`` in ``spec.protocol``'s layout for up to M detections given in slot order (empty
    slots are zeros). ``agent_heading_rad (N,)`` (NaN = never heard) is needed with ``spec.relative_headings``."""
    n = len(probability)
    if n > spec.n_slots:
        raise ValueError(f"{n} detections for {spec.n_slots} slots; select the most probable first")
    slots = np.zeros((spec.n_slots, spec.slot_width))
    slots[:n, 0:2] = position_m
    if spec.protocol == "paper":  # x, y, φ / π, γ
        slots[:n, 2] = encode_agents_paper(np.asarray(heading_rad, dtype=float))
        slots[:n, 3] = probability
        return slots.reshape(-1)
    slots[:n, 2] = np.cos(heading_rad)
    slots[:n, 3] = np.sin(heading_rad)
    slots[:n, 4] = probability
    if spec.relative_headings:
        if agent_heading_rad is None:
            raise ValueError("relative_headings needs the agents' latest headings")
        slots[:n, SLOT_WIDTH:] = relative_headings(np.asarray(heading_rad), np.asarray(agent_heading_rad))
    return slots.reshape(-1)


def relative_headings(slot_heading_rad: np.ndarray, agent_heading_rad: np.ndarray) -> np.ndarray:
    """``cos, sin`` of every slot's heading minus every agent's: ``(..., M, 2N)`` from ``(..., M)``
    and ``(..., N)``; zeros for agents whose heading is NaN."""
    agent = np.asarray(agent_heading_rad, dtype=float)
    known = np.isfinite(agent)[..., None, :]
    agent_or_zero = np.where(np.isfinite(agent), agent, 0.0)
    diff = np.asarray(slot_heading_rad, dtype=float)[..., :, None] - agent_or_zero[..., None, :]
    out = np.stack([np.where(known, np.cos(diff), 0.0), np.where(known, np.sin(diff), 0.0)], axis=-1)
    return out.reshape(*out.shape[:-2], out.shape[-2] * out.shape[-1])


def encode_agents_paper(heading_rad: np.ndarray) -> np.ndarray:
    """The paper's agent inputs ``(..., N)``: latest reported headings ``ψ / π`` in (-1, 1], wrapped;
    0 for an agent never heard from (NaN)."""
    heading = np.asarray(heading_rad, dtype=float)
    known = np.isfinite(heading)
    wrapped = np.angle(np.exp(1j * np.where(known, heading, 0.0)))
    return np.where(known, wrapped / np.pi, 0.0)


def encode_frame(spec: EncodingSpec, detections: Detections, latest_heading_rad: np.ndarray,
                 report_age_s: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """One frame's input ``(n_inputs,)`` in the layout of ``spec.protocol`` (the paper's ignores ``report_age_s``) and
    the detection index of each used slot ``(k,)``: the M most probable detections, most probable first."""
    if detections.position is None or detections.heading is None or detections.score is None:
        raise ValueError("the LSTM encoding needs Detections.position, Detections.heading and Detections.score")
    used = np.argsort(-np.asarray(detections.score), kind="stable")[: spec.n_slots]
    slots = encode_slots(spec, detections.position[used], detections.heading[used], detections.score[used],
                         latest_heading_rad)
    if spec.protocol == "paper":
        return np.concatenate([encode_agents_paper(latest_heading_rad), slots]), used
    agents = encode_agents(spec, np.asarray(latest_heading_rad)[None], np.asarray(report_age_s)[None])[0]
    return np.concatenate([agents, slots]), used
