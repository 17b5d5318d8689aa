"""Identical humanoid robots (coloured cuboids, painted far to near) on a football field, drawn through
:class:`lookalike.geometry.Camera` with seeded lighting drift, blur and noise; with per-robot ground truth."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from lookalike._optional import needs
from lookalike.geometry.camera import Camera, Pose2D

BGR = tuple[int, int, int]

# (name, (x0, x1), (y0, y1), (z0, z1), colour BGR) in the robot's body frame (metres, x forward).
PARTS: tuple[tuple[str, tuple[float, float], tuple[float, float], tuple[float, float], BGR], ...] = (
    ("leg_l", (-0.045, 0.045), (0.025, 0.095), (0.0, 0.28), (45, 45, 50)),
    ("leg_r", (-0.045, 0.045), (-0.095, -0.025), (0.0, 0.28), (45, 45, 50)),
    ("torso", (-0.07, 0.07), (-0.12, 0.12), (0.28, 0.50), (225, 225, 225)),
    ("chest", (0.07, 0.078), (-0.07, 0.07), (0.34, 0.46), (20, 120, 240)),
    ("pack", (-0.10, -0.07), (-0.08, 0.08), (0.30, 0.48), (90, 40, 30)),
    ("arm_l", (-0.04, 0.04), (0.12, 0.16), (0.24, 0.49), (110, 110, 115)),
    ("arm_r", (-0.04, 0.04), (-0.16, -0.12), (0.24, 0.49), (110, 110, 115)),
    ("head", (-0.06, 0.06), (-0.06, 0.06), (0.50, 0.62), (235, 235, 235)),
    ("visor", (0.06, 0.066), (-0.045, 0.045), (0.545, 0.585), (25, 25, 25)),
)
ROBOT_HEIGHT_M = 0.62
ROBOT_WIDTH_M = 0.32

# Face k of a cuboid: corner indices (corner bit 0: x, bit 1: y, bit 2: z) and outward normal.
_FACES = (
    ((1, 3, 7, 5), (1, 0, 0)),
    ((0, 4, 6, 2), (-1, 0, 0)),
    ((2, 6, 7, 3), (0, 1, 0)),
    ((0, 1, 5, 4), (0, -1, 0)),
    ((4, 5, 7, 6), (0, 0, 1)),
    ((0, 2, 3, 1), (0, 0, -1)),
)


@dataclass(frozen=True)
class RenderConfig:
    """Look of the world: field size (m), line width (m), colours, and per-frame nuisances."""

    field_m: tuple[float, float] = (9.0, 6.0)
    line_m: float = 0.05
    grass: BGR = (40, 130, 50)
    sky: BGR = (150, 140, 120)
    brightness_std: float = 0.15  # spread of the slowly varying global gain (1 = nominal)
    cast_std: float = 0.06  # spread of the per-channel colour cast
    blur_max_px: float = 1.5  # Gaussian blur sigma drawn uniformly in [0, blur_max_px] per frame
    noise_std: float = 4.0  # pixel noise, grey levels

    def __post_init__(self) -> None:
        if min(self.field_m) <= 0 or self.line_m <= 0:
            raise ValueError(f"RenderConfig.field_m/line_m: must be positive, got {self.field_m}, {self.line_m}")
        for name in ("brightness_std", "cast_std", "blur_max_px", "noise_std"):
            if getattr(self, name) < 0:
                raise ValueError(f"RenderConfig.{name}: must be >= 0, got {getattr(self, name)!r}")


@dataclass(frozen=True)
class RenderedFrame:
    """One image and its ground truth; rows are the robots that appear in the image.

    Attributes:
        image: ``(h, w, 3)`` uint8 BGR.
        robot_id: ``(n,)`` index of the robot in the input arrays.
        xywh: ``(n, 4)`` box of the visible extent, clipped to the image (px).
        xywh_full: ``(n, 4)`` box of the whole robot, not clipped (px).
        visible: ``(n,)`` fraction of the robot's silhouette that is visible (not hidden by others or the border).
        position_m: ``(n, 2)`` egocentric ground position (m).
        heading_rad: ``(n,)`` egocentric heading (rad, 0 = facing the observer's forward direction)."""

    image: np.ndarray
    robot_id: np.ndarray
    xywh: np.ndarray
    xywh_full: np.ndarray
    visible: np.ndarray
    position_m: np.ndarray
    heading_rad: np.ndarray


@dataclass
class RobotRenderer:
    """Renders frames of ``camera``; one instance per video (it keeps the lighting random walk)."""

    camera: Camera = field(default_factory=Camera.default)
    config: RenderConfig = field(default_factory=RenderConfig)
    seed: int = 0
    _rng: np.random.Generator = field(init=False, repr=False)
    _gain: np.ndarray = field(init=False, repr=False)
    _ground: np.ndarray = field(init=False, repr=False)

    def __post_init__(self) -> None:
        self._rng = np.random.default_rng(self.seed)
        self._gain = np.ones(3)
        k = self.camera.intrinsics
        v, u = np.mgrid[: k.height, : k.width]
        uv = np.column_stack([u.ravel() + 0.5, v.ravel() + 0.5])
        self._ground = self.camera.pixels_to_ground(uv).reshape(k.height, k.width, 2)
        texture = np.random.default_rng(self.seed + 7919).normal(0.0, 1.0, (k.height // 4 + 1, k.width // 4 + 1))
        self._texture = np.kron(texture, np.ones((4, 4)))[: k.height, : k.width]

    def render(
        self, positions_m: np.ndarray, headings_rad: np.ndarray, observer: Pose2D | None = None
    ) -> RenderedFrame:
        """Draw robots at fixed-frame ``positions_m (N, 2)``, ``headings_rad (N,)`` seen from ``observer``."""
        with needs("cv2"):
            import cv2

        pos = np.asarray(positions_m, dtype=float).reshape(-1, 2) if np.size(positions_m) else np.zeros((0, 2))
        head = np.asarray(headings_rad, dtype=float).reshape(-1)
        if len(head) != len(pos):
            raise ValueError(f"headings_rad: {len(head)} values for {len(pos)} positions")
        if not (np.isfinite(pos).all() and np.isfinite(head).all()):
            raise ValueError("positions_m/headings_rad: must be finite")
        obs = observer or Pose2D()
        ego = obs.fixed_to_ego(pos)
        ego_heading = np.asarray(obs.heading_to_ego(head), dtype=float).reshape(-1)
        k = self.camera.intrinsics
        img = self._background(obs)
        ids = np.zeros((k.height, k.width), dtype=np.int32)
        cam_c = self.camera.centre_m
        order = np.argsort(-np.hypot(ego[:, 0], ego[:, 1]))
        full_boxes = np.full((len(pos), 4), np.nan)
        full_area = np.zeros(len(pos))
        light = np.array([0.4, 0.3, 0.85]) / np.linalg.norm([0.4, 0.3, 0.85])
        for i in order:
            polys = self._robot_polygons(ego[i], ego_heading[i], cam_c, light)
            if not polys:
                continue
            pts = np.concatenate([p for p, _ in polys])
            x0, y0 = np.floor(pts.min(axis=0))
            x1, y1 = np.ceil(pts.max(axis=0))
            full_boxes[i] = (x0, y0, x1 - x0, y1 - y0)
            alone = np.zeros((int(y1 - y0) + 1, int(x1 - x0) + 1), np.uint8)
            for poly, colour in polys:
                q = np.round(poly * 16).astype(np.int32)
                cv2.fillConvexPoly(img, q, colour, cv2.LINE_AA, 4)
                cv2.fillConvexPoly(ids, q, int(i) + 1, cv2.LINE_8, 4)
                cv2.fillConvexPoly(alone, np.round((poly - (x0, y0)) * 16).astype(np.int32), 1, cv2.LINE_8, 4)
            full_area[i] = alone.sum()
        img = self._nuisances(img)
        rows = []
        for i in range(len(pos)):
            mask = ids == i + 1
            count = int(mask.sum())
            if count == 0:
                continue
            ys, xs = np.nonzero(mask)
            box = (xs.min(), ys.min(), xs.max() + 1 - xs.min(), ys.max() + 1 - ys.min())
            rows.append((i, box, min(1.0, count / max(full_area[i], 1.0))))
        sel = np.array([r[0] for r in rows], dtype=int)
        return RenderedFrame(
            image=img, robot_id=sel, xywh=np.array([r[1] for r in rows], dtype=float).reshape(-1, 4),
            xywh_full=full_boxes[sel].reshape(-1, 4), visible=np.array([r[2] for r in rows], dtype=float),
            position_m=ego[sel].reshape(-1, 2), heading_rad=ego_heading[sel],
        )

    def _robot_polygons(
        self, xy: np.ndarray, heading: float, cam_c: np.ndarray, light: np.ndarray
    ) -> list[tuple[np.ndarray, BGR]]:
        c, s = np.cos(heading), np.sin(heading)
        rot = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
        origin = np.array([xy[0], xy[1], 0.0])
        parts = []
        for _, xs, ys, zs, colour in PARTS:
            corners = np.array([[xs[b & 1], ys[(b >> 1) & 1], zs[(b >> 2) & 1]] for b in range(8)])
            world = corners @ rot.T + origin
            if (self.camera.depth_m(world) < 0.05).any():
                return []  # part of the robot is behind the camera: not drawn at all
            parts.append((np.linalg.norm(world.mean(axis=0) - cam_c), world, colour))
        parts.sort(key=lambda p: -p[0])
        out = []
        for _, world, colour in parts:
            uv = self.camera.points_to_pixels(world)
            for idx, normal in _FACES:
                n = rot @ np.array(normal, dtype=float)
                centre = world[list(idx)].mean(axis=0)
                if n @ (cam_c - centre) <= 0:
                    continue
                shade = 0.55 + 0.45 * max(0.0, float(n @ light))
                b, g, r = (int(min(255, ch * shade)) for ch in colour)
                out.append((uv[list(idx)], (b, g, r)))
        return out

    def _background(self, obs: Pose2D) -> np.ndarray:
        cfg, k = self.config, self.camera.intrinsics
        g = self._ground.reshape(-1, 2)
        on_ground = np.isfinite(g[:, 0])
        img = np.empty((k.height * k.width, 3), np.float32)
        img[:] = cfg.sky
        fixed = obs.ego_to_fixed(g[on_ground])
        fx, fy = np.abs(fixed[:, 0]), np.abs(fixed[:, 1])
        lx, ly = 0.5 * cfg.field_m[0], 0.5 * cfg.field_m[1]
        half = 0.5 * cfg.line_m
        line = (np.abs(fx - lx) < half) & (fy <= ly + half)
        line |= (np.abs(fy - ly) < half) & (fx <= lx + half)
        line |= (fx < half) & (fy <= ly)  # half-way line
        line |= np.abs(np.hypot(fixed[:, 0], fixed[:, 1]) - 0.75) < half  # centre circle
        grass = np.array(cfg.grass, np.float32)[None] * (1.0 + 0.06 * self._texture.reshape(-1)[on_ground, None])
        grass[line] = (235, 235, 235)
        img[on_ground] = grass
        return np.clip(img, 0, 255).reshape(k.height, k.width, 3).astype(np.uint8)

    def _nuisances(self, img: np.ndarray) -> np.ndarray:
        with needs("cv2"):
            import cv2

        cfg, rng = self.config, self._rng
        target = np.exp(rng.normal(0.0, cfg.brightness_std)) * np.exp(rng.normal(0.0, cfg.cast_std, 3))
        self._gain = 0.8 * self._gain + 0.2 * target  # slow drift of the lighting
        sigma = rng.uniform(0.0, cfg.blur_max_px)
        out: np.ndarray = img.astype(np.float32)
        if sigma > 0.3:
            out = cv2.GaussianBlur(out, (0, 0), sigma)
        out = out * self._gain[None, None, :].astype(np.float32)
        out += rng.normal(0.0, cfg.noise_std, out.shape).astype(np.float32)
        return np.clip(out, 0, 255).astype(np.uint8)
