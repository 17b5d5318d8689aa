"""Look-alike divers drawn as camera images: a jointed figure (metres, x towards the head) projected with
``scale = focal_px / z``, mirrored by facing, rotated by pitch, faded and blurred with distance."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from lookalike._optional import needs

BGR = tuple[int, int, int]


@dataclass(frozen=True)
class DiverLook:
    """What tells one diver from another: colours (BGR) and body size; differences are subtle."""

    suit: BGR
    accent: BGR  # stripes on arms and legs
    tank: BGR
    fins: BGR
    hood: BGR
    size: float = 1.0  # body length factor


#: A team in near-identical gear: dark suits, but different tanks, fins and stripes.
TEAM: tuple[DiverLook, ...] = (
    DiverLook(suit=(32, 30, 28), accent=(32, 30, 28), tank=(20, 190, 225), fins=(30, 30, 30), hood=(32, 30, 28)),
    DiverLook(suit=(40, 34, 30), accent=(140, 60, 20), tank=(175, 175, 170), fins=(25, 25, 25), hood=(40, 34, 30),
              size=1.06),
    DiverLook(suit=(30, 30, 36), accent=(30, 30, 36), tank=(30, 200, 230), fins=(120, 70, 20), hood=(60, 60, 60),
              size=0.95),
    DiverLook(suit=(36, 36, 34), accent=(40, 40, 150), tank=(160, 165, 175), fins=(35, 35, 35), hood=(36, 36, 34),
              size=1.0),
)


@dataclass(frozen=True)
class Pose:
    """One diver in one frame: image centre (px), distance (m), facing (+1 right, -1 left),
    pitch (rad), stroke phase (rad) and arm pose (0 along the body .. 1 stretched forward)."""

    cx: float
    cy: float
    z: float
    facing: float
    pitch: float
    phase: float
    arms: float


def _segments(pose: Pose, size: float) -> dict[str, np.ndarray]:
    """Key points in body coordinates (metres)."""
    kick = 0.22 * np.sin(pose.phase)
    reach = 0.35 + 0.45 * pose.arms
    arm_y = 0.05 - 0.1 * (1 - pose.arms)
    pts = {
        "torso": np.array([0.3, 0.0]),
        "head": np.array([0.88, -0.02]),
        "tank_a": np.array([0.05, -0.2]),
        "tank_b": np.array([0.65, -0.2]),
        "hip": np.array([-0.15, 0.0]),
        "knee1": np.array([-0.55, kick * 0.5]),
        "knee2": np.array([-0.55, -kick * 0.5]),
        "ankle1": np.array([-0.92, kick]),
        "ankle2": np.array([-0.92, -kick]),
        "fin1": np.array([-1.22, 1.6 * kick]),
        "fin2": np.array([-1.22, -1.6 * kick]),
        "shoulder": np.array([0.6, 0.06]),
        "hand": np.array([0.6 + reach, arm_y]),
    }
    return {k: v * size for k, v in pts.items()}


def project(pose: Pose, size: float, focal_px: float) -> dict[str, np.ndarray]:
    """Key points in image pixels ``(2,)`` for one pose."""
    s = focal_px / pose.z
    c, sn = np.cos(pose.pitch), np.sin(pose.pitch)
    rot = np.array([[c, -sn], [sn, c]])
    out = {}
    for name, p in _segments(pose, size).items():
        q = rot @ np.array([pose.facing * p[0], p[1]])
        out[name] = np.array([pose.cx, pose.cy]) + s * q
    return out


def diver_box(pose: Pose, size: float, focal_px: float) -> np.ndarray:
    """The tight ``(4,)`` ``xywh`` box (pixels) of a diver's figure."""
    pts = np.array(list(project(pose, size, focal_px).values()))
    pad = 0.17 * size * focal_px / pose.z  # half the torso thickness
    lo = pts.min(axis=0) - pad
    hi = pts.max(axis=0) + pad
    return np.concatenate([lo, hi - lo])


def attenuate(colour: BGR, water: np.ndarray, z: float, attenuation: float) -> tuple[float, float, float]:
    """Colour seen through ``z`` metres of water with coefficient ``attenuation`` (1/m)."""
    keep = np.exp(-attenuation * z)
    c = water + (np.asarray(colour, float) - water) * keep
    return (float(c[0]), float(c[1]), float(c[2]))


def draw_diver(image: np.ndarray, pose: Pose, look: DiverLook, focal_px: float, water: np.ndarray,
               attenuation: float, blur_per_m: float) -> None:
    """Draw one diver in place on ``image (h, w, 3)`` uint8 BGR."""
    with needs("cv2"):
        import cv2

    pts = project(pose, look.size, focal_px)
    s = focal_px / pose.z * look.size
    col = {k: attenuate(getattr(look, k), water, pose.z, attenuation)
           for k in ("suit", "accent", "tank", "fins", "hood")}

    def P(name: str) -> tuple[int, int]:
        return round(pts[name][0]), round(pts[name][1])

    def thick(m: float) -> int:
        return max(round(m * s), 1)

    box = diver_box(pose, look.size, focal_px)
    h, w = image.shape[:2]
    x0, y0 = max(int(box[0]) - 4, 0), max(int(box[1]) - 4, 0)
    x1, y1 = min(int(box[0] + box[2]) + 5, w), min(int(box[1] + box[3]) + 5, h)
    if x1 <= x0 or y1 <= y0:
        return
    angle = float(np.degrees(pose.pitch))
    for leg in ("1", "2"):
        cv2.line(image, P("hip"), P("knee" + leg), col["suit"], thick(0.15), cv2.LINE_AA)
        cv2.line(image, P("knee" + leg), P("ankle" + leg), col["accent"], thick(0.12), cv2.LINE_AA)
        cv2.line(image, P("ankle" + leg), P("fin" + leg), col["fins"], thick(0.1), cv2.LINE_AA)
        cv2.circle(image, P("fin" + leg), thick(0.07), col["fins"], -1, cv2.LINE_AA)
    cv2.ellipse(image, P("torso"), (thick(0.5), thick(0.17)), angle, 0, 360, col["suit"], -1, cv2.LINE_AA)
    cv2.line(image, P("tank_a"), P("tank_b"), col["tank"], thick(0.13), cv2.LINE_AA)
    cv2.line(image, P("shoulder"), P("hand"), col["accent"], thick(0.09), cv2.LINE_AA)
    cv2.circle(image, P("head"), thick(0.12), col["hood"], -1, cv2.LINE_AA)
    sigma = blur_per_m * pose.z
    if sigma > 0.3:
        region = image[y0:y1, x0:x1]
        image[y0:y1, x0:x1] = cv2.GaussianBlur(region, (0, 0), sigma)


def draw_bubbles(image: np.ndarray, centres: np.ndarray, radii: np.ndarray, colour: BGR, alpha: float) -> None:
    """Blend bubbles (circles, ``centres (k, 2)``, ``radii (k,)`` in pixels) into ``image`` in place."""
    with needs("cv2"):
        import cv2

    if not len(centres):
        return
    layer = image.copy()
    for (x, y), r in zip(centres, radii):
        cv2.circle(layer, (int(x), int(y)), max(int(r), 1), colour, -1, cv2.LINE_AA)
    cv2.addWeighted(layer, alpha, image, 1 - alpha, 0, dst=image)


def background(width: int, height: int, water: np.ndarray, margin: int) -> np.ndarray:
    """A ``(height + 2·margin, width + 2·margin, 3)`` uint8 water backdrop, brighter towards the surface."""
    rows = height + 2 * margin
    light = np.linspace(1.35, 0.7, rows)[:, None, None]
    cols = np.linspace(0.95, 1.05, width + 2 * margin)[None, :, None]
    return np.clip(water[None, None, :] * light * cols, 0, 255).astype(np.uint8)
