"""Pinhole camera over a flat ground plane (no lens distortion), and observer odometry. Frames: egocentric (metres,
origin on the ground below the camera, x forward, y left, z up), camera (x right, y down, z along the optical axis),
image (pixels, u right, v down, origin at the top-left corner)."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

# Camera axes expressed in the egocentric frame for a level camera looking along +x:
# optical x (right) = -y, optical y (down) = -z, optical z (forward) = +x.
_LEVEL = np.array([[0.0, 0.0, 1.0], [-1.0, 0.0, 0.0], [0.0, -1.0, 0.0]])


def _positive(owner: str, name: str, value: float) -> float:
    v = float(value)
    if not math.isfinite(v) or v <= 0:
        raise ValueError(f"{owner}.{name}: must be a positive finite number, got {value!r}")
    return v


def _finite(owner: str, name: str, value: float) -> float:
    v = float(value)
    if not math.isfinite(v):
        raise ValueError(f"{owner}.{name}: must be finite, got {value!r}")
    return v


@dataclass(frozen=True)
class Intrinsics:
    """Pinhole intrinsics: focal lengths and principal point in pixels, image size in pixels."""

    fx: float
    fy: float
    cx: float
    cy: float
    width: int
    height: int

    def __post_init__(self) -> None:
        for name in ("fx", "fy"):
            object.__setattr__(self, name, _positive("Intrinsics", name, getattr(self, name)))
        for name in ("cx", "cy"):
            object.__setattr__(self, name, _finite("Intrinsics", name, getattr(self, name)))
        for name in ("width", "height"):
            v = getattr(self, name)
            if int(v) != v or v <= 0:
                raise ValueError(f"Intrinsics.{name}: must be a positive integer, got {v!r}")
            object.__setattr__(self, name, int(v))

    @classmethod
    def from_fov(cls, width: int, height: int, hfov_rad: float) -> Intrinsics:
        """Square pixels, principal point at the image centre, horizontal field of view ``hfov_rad``."""
        if not 0 < hfov_rad < math.pi:
            raise ValueError(f"Intrinsics.from_fov: hfov_rad must be in (0, π), got {hfov_rad!r}")
        f = 0.5 * width / math.tan(0.5 * hfov_rad)
        return cls(fx=f, fy=f, cx=0.5 * width, cy=0.5 * height, width=width, height=height)

    @property
    def matrix(self) -> np.ndarray:
        """The ``(3, 3)`` calibration matrix K."""
        return np.array([[self.fx, 0.0, self.cx], [0.0, self.fy, self.cy], [0.0, 0.0, 1.0]])


@dataclass(frozen=True)
class Extrinsics:
    """Camera pose in the egocentric frame: height above ground (m) and yaw/pitch/roll (rad)."""

    height_m: float
    pitch_rad: float = 0.0
    roll_rad: float = 0.0
    yaw_rad: float = 0.0

    def __post_init__(self) -> None:
        object.__setattr__(self, "height_m", _positive("Extrinsics", "height_m", self.height_m))
        for name in ("pitch_rad", "roll_rad", "yaw_rad"):
            object.__setattr__(self, name, _finite("Extrinsics", name, getattr(self, name)))
        if abs(self.pitch_rad) >= math.pi / 2:
            raise ValueError(f"Extrinsics.pitch_rad: must be within (-π/2, π/2), got {self.pitch_rad!r}")

    @property
    def rotation(self) -> np.ndarray:
        """``(3, 3)`` rotation taking camera-frame vectors to egocentric vectors."""
        cy, sy = math.cos(self.yaw_rad), math.sin(self.yaw_rad)
        cp, sp = math.cos(self.pitch_rad), math.sin(self.pitch_rad)
        cr, sr = math.cos(self.roll_rad), math.sin(self.roll_rad)
        yaw = np.array([[cy, -sy, 0.0], [sy, cy, 0.0], [0.0, 0.0, 1.0]])
        pitch = np.array([[cp, 0.0, sp], [0.0, 1.0, 0.0], [-sp, 0.0, cp]])  # +pitch: forward tilts down
        roll = np.array([[cr, -sr, 0.0], [sr, cr, 0.0], [0.0, 0.0, 1.0]])  # about the optical axis
        result: np.ndarray = yaw @ pitch @ _LEVEL @ roll
        return result


@dataclass(frozen=True)
class Camera:
    """A calibrated camera above flat ground; every method is batched over rows."""

    intrinsics: Intrinsics
    extrinsics: Extrinsics
    _r: np.ndarray = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        if not isinstance(self.intrinsics, Intrinsics):
            raise ValueError(f"Camera.intrinsics: expected Intrinsics, got {type(self.intrinsics).__name__}")
        if not isinstance(self.extrinsics, Extrinsics):
            raise ValueError(f"Camera.extrinsics: expected Extrinsics, got {type(self.extrinsics).__name__}")
        r = self.extrinsics.rotation
        r.setflags(write=False)
        object.__setattr__(self, "_r", r)

    @classmethod
    def default(cls, width: int = 640, height: int = 480) -> Camera:
        """A robot-head camera: 0.9 m high, 25° down, 70° horizontal field of view."""
        return cls(Intrinsics.from_fov(width, height, math.radians(70.0)), Extrinsics(0.9, math.radians(25.0)))

    @property
    def centre_m(self) -> np.ndarray:
        """Camera centre ``(3,)`` in the egocentric frame (metres)."""
        return np.array([0.0, 0.0, self.extrinsics.height_m])

    def points_to_pixels(self, points_m: np.ndarray) -> np.ndarray:
        """Project egocentric points ``(n, 3)`` (m) to pixels ``(n, 2)``; NaN for points behind the camera."""
        p = _rows("points_m", points_m, 3)
        cam = (p - self.centre_m) @ self._r  # rows: R^T (p - c)
        k = self.intrinsics
        with np.errstate(divide="ignore", invalid="ignore"):
            u = k.fx * cam[:, 0] / cam[:, 2] + k.cx
            v = k.fy * cam[:, 1] / cam[:, 2] + k.cy
        out = np.stack([u, v], axis=1)
        out[cam[:, 2] <= 1e-9] = np.nan
        return out

    def depth_m(self, points_m: np.ndarray) -> np.ndarray:
        """Distance of points ``(n, 3)`` along the optical axis, metres ``(n,)`` (negative: behind)."""
        p = _rows("points_m", points_m, 3)
        result: np.ndarray = (p - self.centre_m) @ self._r[:, 2]
        return result

    def ground_to_pixels(self, position_m: np.ndarray, z_m: float | np.ndarray = 0.0) -> np.ndarray:
        """Pixels ``(n, 2)`` of egocentric ground positions ``(n, 2)`` lifted to height ``z_m``."""
        xy = _rows("position_m", position_m, 2)
        z = np.broadcast_to(np.asarray(z_m, dtype=float), (len(xy),))
        return self.points_to_pixels(np.column_stack([xy, z]))

    def pixels_to_ground(self, uv_px: np.ndarray, z_m: float = 0.0) -> np.ndarray:
        """Where the rays through pixels ``(n, 2)`` meet the plane ``z = z_m``, egocentric ``(n, 2)``; NaN if never."""
        uv = _rows("uv_px", uv_px, 2)
        k = self.intrinsics
        rays_cam = np.column_stack([(uv[:, 0] - k.cx) / k.fx, (uv[:, 1] - k.cy) / k.fy, np.ones(len(uv))])
        rays = rays_cam @ self._r.T
        drop = self.extrinsics.height_m - float(z_m)
        with np.errstate(divide="ignore", invalid="ignore"):
            s = -drop / rays[:, 2]
        out = rays[:, :2] * s[:, None]
        out[~(s > 0)] = np.nan
        result: np.ndarray = out
        return result

    def box_to_ground(self, xywh: np.ndarray) -> np.ndarray:
        """Ground positions ``(n, 2)`` (m) of the bottom centres of boxes ``xywh (n, 4)``; NaN above the horizon."""
        b = _rows("xywh", xywh, 4)
        return self.pixels_to_ground(np.column_stack([b[:, 0] + 0.5 * b[:, 2], b[:, 1] + b[:, 3]]))

    def ground_to_box(self, position_m: np.ndarray, height_m: float, width_m: float) -> np.ndarray:
        """Boxes ``xywh (n, 4)`` (px) of upright objects ``height_m`` tall and ``width_m`` wide standing at
        ground positions ``(n, 2)``: the box's bottom-centre is the foot point, so
        ``box_to_ground(ground_to_box(p, ...)) == p``. NaN rows for objects behind the camera."""
        xy = _rows("position_m", position_m, 2)
        _positive("Camera.ground_to_box", "height_m", height_m)
        _positive("Camera.ground_to_box", "width_m", width_m)
        foot = self.ground_to_pixels(xy, 0.0)
        head = self.ground_to_pixels(xy, height_m)
        # Half-width: project the two ends of a horizontal segment across the viewing direction.
        view = xy - self.centre_m[:2]
        norm = np.linalg.norm(view, axis=1, keepdims=True)
        side = np.column_stack([-view[:, 1], view[:, 0]]) / np.where(norm > 0, norm, 1.0)
        mid_z = 0.5 * height_m
        left = self.ground_to_pixels(xy + 0.5 * width_m * side, mid_z)
        right = self.ground_to_pixels(xy - 0.5 * width_m * side, mid_z)
        w = np.abs(right[:, 0] - left[:, 0])
        h = foot[:, 1] - head[:, 1]
        return np.column_stack([foot[:, 0] - 0.5 * w, foot[:, 1] - h, w, h])



@dataclass(frozen=True)
class Pose2D:
    """Observer pose in a fixed (world) frame: position (m) and heading (rad, counter-clockwise from x)."""

    x_m: float = 0.0
    y_m: float = 0.0
    heading_rad: float = 0.0

    def __post_init__(self) -> None:
        for name in ("x_m", "y_m", "heading_rad"):
            object.__setattr__(self, name, _finite("Pose2D", name, getattr(self, name)))

    def _rot(self) -> np.ndarray:
        c, s = math.cos(self.heading_rad), math.sin(self.heading_rad)
        return np.array([[c, -s], [s, c]])

    def ego_to_fixed(self, position_m: np.ndarray) -> np.ndarray:
        """Egocentric positions ``(n, 2)`` (m) as positions in the fixed frame ``(n, 2)``."""
        xy = _rows("position_m", position_m, 2)
        result: np.ndarray = xy @ self._rot().T + np.array([self.x_m, self.y_m])
        return result

    def fixed_to_ego(self, position_m: np.ndarray) -> np.ndarray:
        """Fixed-frame positions ``(n, 2)`` (m) in this observer's egocentric frame ``(n, 2)``."""
        xy = _rows("position_m", position_m, 2)
        result: np.ndarray = (xy - np.array([self.x_m, self.y_m])) @ self._rot()
        return result

    def heading_to_fixed(self, heading_rad: np.ndarray) -> np.ndarray:
        """Egocentric headings ``(n,)`` as fixed-frame headings in (-π, π]."""
        h = np.asarray(heading_rad, dtype=float) + self.heading_rad
        return np.pi - np.mod(np.pi - h, 2.0 * np.pi)

    def heading_to_ego(self, heading_rad: np.ndarray) -> np.ndarray:
        """Fixed-frame headings ``(n,)`` as egocentric headings in (-π, π]."""
        h = np.asarray(heading_rad, dtype=float) - self.heading_rad
        return np.pi - np.mod(np.pi - h, 2.0 * np.pi)

    def compose(self, dx_m: float, dy_m: float, dheading_rad: float) -> Pose2D:
        """The pose after an odometry step ``(dx, dy, dθ)`` measured in this pose's own frame."""
        c, s = math.cos(self.heading_rad), math.sin(self.heading_rad)
        h = self.heading_rad + float(dheading_rad)
        return Pose2D(self.x_m + c * dx_m - s * dy_m, self.y_m + s * dx_m + c * dy_m, _wrap(h))

    def relative_to(self, other: Pose2D) -> tuple[float, float, float]:
        """The odometry step ``(dx, dy, dθ)`` that takes ``other`` to this pose (in ``other``'s frame)."""
        d = other.fixed_to_ego(np.array([[self.x_m, self.y_m]]))[0]
        return float(d[0]), float(d[1]), _wrap(self.heading_rad - other.heading_rad)


def integrate_odometry(steps: np.ndarray, start: Pose2D | None = None) -> list[Pose2D]:
    """The ``n + 1`` poses from ``start`` (default origin) through odometry steps ``(n, 3)`` (m, m, rad)."""
    d = _rows("steps", steps, 3)
    poses = [start if start is not None else Pose2D()]
    for dx, dy, dh in d:
        poses.append(poses[-1].compose(dx, dy, dh))
    return poses


def _wrap(a: float) -> float:
    return float(math.pi - ((math.pi - a) % (2.0 * math.pi)))


def _rows(name: str, value: np.ndarray, width: int) -> np.ndarray:
    arr = np.asarray(value, dtype=float)
    if arr.ndim == 1 and arr.shape[0] == width:
        arr = arr[None, :]
    if arr.size == 0:
        arr = arr.reshape(0, width)
    if arr.ndim != 2 or arr.shape[1] != width:
        raise ValueError(f"{name}: expected shape (n, {width}), got {arr.shape}")
    return arr
