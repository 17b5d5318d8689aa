"""Named robot-world scenarios: the paper's set-ups (M detections at most, N robots) at 30 Hz."""

from __future__ import annotations

import dataclasses

from lookalike.sim.robots_config import RobotWorldConfig, SensorConfig

# (M, N, false positives per frame before keeping the M best)
_SETUPS = {"m3n2": (3, 2, 0.5), "m5n3": (5, 3, 0.8), "m10n7": (10, 7, 1.5)}

PRESET_NAMES: tuple[str, ...] = tuple(_SETUPS)


def preset(name: str) -> RobotWorldConfig:
    """The scenario named ``name`` (``m3n2``, ``m5n3`` or ``m10n7``); others raise ``ValueError``."""
    try:
        m, n, fp = _SETUPS[name]
    except KeyError:
        raise ValueError(f"preset: unknown name {name!r}; known: {', '.join(PRESET_NAMES)}") from None
    return RobotWorldConfig(n_agents=n, max_detections=m, frame_rate_hz=30.0,
                            sensor=dataclasses.replace(SensorConfig(), fp_per_frame=fp))


def preset_label(name: str) -> str:
    """``"M=3, N=2"`` style label of a preset, as in the paper's tables."""
    cfg = preset(name)
    return f"M={cfg.max_detections}, N={cfg.n_agents}"
