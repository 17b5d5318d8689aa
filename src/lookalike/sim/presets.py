"""Robot-world scenarios (teams) at 30 Hz: the paper's set-ups by name (``m3n2``, ``m5n3``, ``m10n7``: M detections kept
per frame at most, N robots) or any team ``mMnN`` (also ``nNmM``), optionally ``…fpF`` for F false positives per frame
(default ``0.1 + 0.2·N``, near the named set-ups' 0.5, 0.8 and 1.5). Position noise ``"paper"`` (Farazi and Behnke's:
lateral std ``0.05 + 0.04·d``, depth ``0.03 + 0.015·d`` metres at distance ``d``) or ``"ours"`` (the same laws on the
other axes; the default, on which the shipped weights were trained)."""

from __future__ import annotations

import dataclasses
import re

from lookalike.sim.robots_config import RobotWorldConfig, SensorConfig

# (M, N, false positives per frame before keeping the M best)
_SETUPS = {"m3n2": (3, 2, 0.5), "m5n3": (5, 3, 0.8), "m10n7": (10, 7, 1.5)}

PRESET_NAMES: tuple[str, ...] = tuple(_SETUPS)
NOISE_MODELS: tuple[str, ...] = ("paper", "ours")
DEFAULT_NOISE = "ours"
MAX_TEAM = 1000  # most robots and most kept detections of a team
_TEAM = re.compile(r"(?:m(?P<m>\d+)n(?P<n>\d+)|n(?P<n2>\d+)m(?P<m2>\d+))(?:fp(?P<fp>\d+(?:\.\d*)?))?")
TEAM_HELP = f"{', '.join(PRESET_NAMES)}, or any team mMnN[fpF]: M detections per frame, N robots, F false positives"


def team_size(name: str) -> tuple[int, int, float]:
    """``(M, N, false positives per frame)`` of a named set-up or of a team ``mMnN[fpF]`` / ``nNmM[fpF]``."""
    if name in _SETUPS:
        return _SETUPS[name]
    found = _TEAM.fullmatch(name)
    if found is None:
        raise ValueError(f"unknown team {name!r}; give {TEAM_HELP} (e.g. m7n4 or m15n12fp2.5)")
    m, n = int(found["m"] or found["m2"]), int(found["n"] or found["n2"])
    if not (1 <= m <= MAX_TEAM and 1 <= n <= MAX_TEAM):
        raise ValueError(f"team {name!r}: M and N must lie in 1..{MAX_TEAM}")
    return m, n, float(found["fp"]) if found["fp"] else round(0.1 + 0.2 * n, 2)


def team_index(name: str) -> int:
    """A team's place in seed rules ``seed + 1000·index + k``: 0, 1, 2 for the named set-ups, else ``1000·N + M``."""
    if name in _SETUPS:
        return PRESET_NAMES.index(name)
    m, n, _ = team_size(name)
    return 1000 * n + m


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
    """The scenario of team ``name`` (``m3n2``, ``m5n3``, ``m10n7`` or ``mMnN[fpF]``) with noise model ``noise``."""
    m, n, fp = team_size(name)
    sensor = dataclasses.replace(noise_sensor(noise), fp_per_frame=fp)
    return RobotWorldConfig(n_agents=n, max_detections=m, frame_rate_hz=30.0, sensor=sensor)


def preset_label(name: str) -> str:
    """``"M=3, N=2"`` style label of a team, as in the paper's tables (``", fp=F"`` added when the name sets it)."""
    m, n, fp = team_size(name)
    return f"M={m}, N={n}" + (f", fp={fp:g}" if "fp" in name else "")
