"""Robots identified from a video's pixels with the heading reports of a ``lookalike simulate`` file (``lookalike track
--video V --pipeline robots``), and robot sequences rendered through the robot camera (``lookalike render-robots``)."""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable, Iterable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from lookalike.geometry.camera import Camera, Pose2D
from lookalike.io.stream import MotWriter
from lookalike.loop import RunStats, run
from lookalike.sim import RobotSequence, RobotWorldConfig
from lookalike.trackers import tracker_parameters
from lookalike.types import Frame
from lookalike.vision.pipeline import PipelineResult, RobotPipeline, labelled_rows


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


@contextmanager
def one_blas_thread() -> Iterator[None]:
    """Limit BLAS to one thread inside the block (threadpoolctl, when installed): faster for the heading SVM."""
    try:
        from threadpoolctl import threadpool_limits
    except ImportError:
        yield
        return
    with threadpool_limits(limits=1, user_api="blas"):
        yield


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


@dataclass(frozen=True)
class PixelFrame:
    """One video frame with the sequence's frame of the same index (reports, time), observer yaw (rad) and the
    observer's field position ``(x, y)`` (m; ``None``: unknown)."""

    index: int
    image: np.ndarray
    frame: Frame
    yaw_rad: float
    xy_m: tuple[float, float] | None = None


def pixel_frames(images: Iterable[np.ndarray], reports: RobotSequence, source: str = "video") -> Iterator[PixelFrame]:
    """The video's frames paired with the report sequence's; ``ValueError`` when the video is longer."""
    for k, image in enumerate(images):
        if k >= len(reports):
            raise ValueError(f"{source}: the reports have {len(reports)} frames, the video more")
        x, y, yaw = (float(v) for v in reports.arrays.observer[k])
        yield PixelFrame(k, image, reports.frame(k), yaw, (x, y))


class PipelineStep:
    """The pipeline as a tracker of :class:`PixelFrame` objects (for :func:`lookalike.loop.run`)."""

    def __init__(self, pipe: RobotPipeline) -> None:
        self.pipe = pipe

    def update(self, frame: PixelFrame) -> PipelineResult:
        """Perceive and identify one frame."""
        return self.pipe.update(frame.image, frame.frame.beacons, frame.frame.time, frame.yaw_rad, frame.xy_m)


def identify_video(pipe: RobotPipeline, frames: Iterable[PixelFrame], output: Path, *,
                   annotate: Callable[[PixelFrame, PipelineResult], None] | None = None,
                   advance: Callable[[], None] | None = None) -> RunStats:
    """Run the pipeline over ``frames``, streaming its rows (:func:`labelled_rows`) to ``output``; ``annotate(frame,
    result)`` sees every frame."""
    with MotWriter(output) as writer:
        def sink(frame: PixelFrame, result: PipelineResult) -> None:
            writer.write_rows(labelled_rows(frame.index, result.detections, result.labels, result.tracks))
            if annotate is not None:
                annotate(frame, result)
            if advance is not None:
                advance()

        with one_blas_thread():
            return run(PipelineStep(pipe), frames, sink)


__all__ = ["PipelineStep", "PixelFrame", "annotate_frame", "hfov_rad", "identifier_settings", "identify_video",
           "one_blas_thread", "pixel_camera", "pixel_frames", "render_robot_frames", "world_for_camera"]
