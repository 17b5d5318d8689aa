"""Robot sequences rendered through the robot camera (``lookalike render-robots``), and a frame of the robots identified
from pixels drawn with its detections (``lookalike track --video V --pipeline robots --annotate``; the run itself:
:mod:`lookalike.pipeline.robots`)."""

from __future__ import annotations

from collections.abc import Iterator
from typing import Any

import numpy as np

from lookalike.geometry.camera import Camera, Pose2D
from lookalike.sim import RobotSequence
from lookalike.vision.pipeline import PipelineResult


def render_robot_frames(sequence: RobotSequence, camera: Camera, seed: int) -> Iterator[Any]:
    """The rendered frame of every frame of ``sequence``, seen from its observer pose."""
    from lookalike.sim.render_robots import RenderConfig, RobotRenderer

    a = sequence.arrays
    renderer = RobotRenderer(camera=camera, config=RenderConfig(field_m=sequence.config.field_m), seed=seed)
    for k in range(len(a)):
        pose = a.observer[k]
        yield renderer.render(a.field_position[k], a.true_heading[k], Pose2D(*(float(v) for v in pose)))


def annotate_frame(image: np.ndarray, result: PipelineResult, caption: list[str]) -> np.ndarray:
    """A copy of ``image`` with each detection boxed in its identity colour (dashed grey: false positive)."""
    from lookalike.viz.annotate import draw_box, draw_caption
    from lookalike.viz.colors import identity_colour

    out = image.copy()
    det = result.detections
    assert det.xywh is not None and det.position is not None  # the pipeline fills both
    for box, lab, pos in zip(det.xywh, result.labels, det.position):
        text = "false positive" if lab < 0 else f"robot {lab + 1} {pos[0]:.1f},{pos[1]:.1f} m"
        draw_box(out, box, identity_colour(int(lab)), label=text, dashed=lab < 0)
    draw_caption(out, caption)
    return out


__all__ = ["annotate_frame", "render_robot_frames"]
