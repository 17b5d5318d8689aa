"""The robot camera: the camera the simulated robots are rendered and identified with, a world's field of view set to
it, and the identifier parameters tied to it."""

from __future__ import annotations

import dataclasses
import math
from typing import Any

from lookalike.geometry.camera import Camera
from lookalike.sim.robots_config import RobotWorldConfig
from lookalike.trackers import tracker_parameters


def pixel_camera() -> Camera:
    """The camera the robots are rendered and identified with (the detector and heading models' own)."""
    return Camera.default()


def hfov_rad(camera: Camera) -> float:
    """Horizontal field of view of ``camera`` (rad)."""
    k = camera.intrinsics
    return 2.0 * math.atan(0.5 * k.width / k.fx)


def world_for_camera(config: RobotWorldConfig, camera: Camera) -> RobotWorldConfig:
    """``config`` with the observer's field of view set to the camera's."""
    return dataclasses.replace(config, observer=dataclasses.replace(config.observer, fov_rad=hfov_rad(camera)))


def identifier_settings(name: str, camera: Camera) -> tuple[tuple[str, Any], ...]:
    """Parameters that tie identifier ``name`` to the camera (its field of view, for out-of-view coasting)."""
    known = {p.name for p in tracker_parameters(name)}
    return (("fov_deg", math.degrees(hfov_rad(camera))),) if "fov_deg" in known else ()



__all__ = ["hfov_rad", "identifier_settings", "pixel_camera", "world_for_camera"]
