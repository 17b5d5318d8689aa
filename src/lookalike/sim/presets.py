"""Named robot-world scenarios: the paper's set-ups (M detections at most, N robots) at 30 Hz, with position noise
``"paper"`` (Farazi and Behnke's: lateral std ``0.05 + 0.04·d``, depth ``0.03 + 0.015·d`` metres at distance ``d``) or
``"ours"`` (the same laws on the other axes; the default, on which the shipped weights were trained)."""

from __future__ import annotations

import dataclasses

from lookalike.sim.robots_config import RobotWorldConfig, SensorConfig

# (M, N, false positives per frame before keeping the M best)
_SETUPS = {"m3n2": (3, 2, 0.5), "m5n3": (5, 3, 0.8), "m10n7": (10, 7, 1.5)}

PRESET_NAMES: tuple[str, ...] = tuple(_SETUPS)
NOISE_MODELS: tuple[str, ...] = ("paper", "ours")
DEFAULT_NOISE = "ours"


def noise_sensor(noise: str, base: SensorConfig | None = None) -> SensorConfig:
    """``base`` (default :class:`SensorConfig`) with the position noise of ``"paper"`` or ``"ours"``."""
    sensor = base or SensorConfig()
    ours = SensorConfig()
    if noise == "ours":
        return dataclasses.replace(sensor, std_x0_m=ours.std_x0_m, std_x_per_m=ours.std_x_per_m,
                                   std_y0_m=ours.std_y0_m, std_y_per_m=ours.std_y_per_m)
    if noise == "paper":  # the larger law across the image (observer y), the smaller in depth (x)
        return dataclasses.replace(sensor, std_x0_m=ours.std_y0_m, std_x_per_m=ours.std_y_per_m,
                                   std_y0_m=ours.std_x0_m, std_y_per_m=ours.std_x_per_m)
    raise ValueError(f"noise: unknown model {noise!r}; known: {', '.join(NOISE_MODELS)}")


def preset(name: str, noise: str = DEFAULT_NOISE) -> RobotWorldConfig:
    """The scenario ``m3n2``, ``m5n3`` or ``m10n7`` with noise model ``noise``."""
    try:
        m, n, fp = _SETUPS[name]
    except KeyError:
        raise ValueError(f"preset: unknown name {name!r}; known: {', '.join(PRESET_NAMES)}") from None
    sensor = dataclasses.replace(noise_sensor(noise), fp_per_frame=fp)
    return RobotWorldConfig(n_agents=n, max_detections=m, frame_rate_hz=30.0, sensor=sensor)


def preset_label(name: str) -> str:
    """``"M=3, N=2"`` style label of a preset, as in the paper's tables."""
    cfg = preset(name)
    return f"M={cfg.max_detections}, N={cfg.n_agents}"
