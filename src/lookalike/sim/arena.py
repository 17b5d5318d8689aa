"""Look-alike animals in a walled arena, seen from above: fish-like bodies on correlated random walks with bursts,
glides, rests and attraction to one another, with known truth; rendered by :mod:`lookalike.sim.arena_render`.

Truth rows: ``(frame 1-based, id 1..N, centre x px, centre y px, heading rad, body length px)``; the centre is the
centroid of the animal's silhouette, the heading points from tail to head (image axes: x right, y down)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

ARENA_SHAPES = ("round", "square")


@dataclass(frozen=True)
class ArenaConfig:
    """An arena of look-alike animals. Lengths in pixels, times in frames, grey levels out of 255.

    The defaults are the documented difficulty, near the zebrafish video ``test_A`` (8 fish about 57 px long, dark on
    a grey-white floor, 28 fps, a median step of 5 px a frame, frequent touching)."""

    n_animals: int = 8
    frames: int = 500
    frame_rate_hz: float = 28.0
    image_px: int = 800  # side of the square image
    shape: str = "round"  # "round" or "square" arena
    margin_px: float = 30.0  # from the image border to the arena wall
    # bodies
    body_length_px: float = 56.0  # mean length, head tip to tail tip
    body_width_px: float = 9.0  # widest point of the body
    size_spread: float = 0.07  # each animal's scale is uniform in 1 ± this (0: all the same size)
    body_darkness: float = 0.45  # share of the light the body absorbs (0: invisible, 1: black)
    head_darkness: float = 0.12  # mean extra absorption of the head; each animal's is uniform in 0.5-1.5 × this
    pattern_darkness: float = 0.06  # extra absorption of each animal's faint band (0: no band)
    body_bend: float = 1.0  # the body curves by this × the heading's change over the last 3 frames (0: rigid)
    # motion
    speed_px: float = 5.5  # mean speed while swimming, px per frame
    burst_rate: float = 0.15  # chance per frame of a tail-beat burst (speed then glides down)
    glide_decay: float = 0.9  # speed kept from one frame to the next between bursts
    turn_rad: float = 0.5  # std of the turn at a burst
    wiggle_rad: float = 0.05  # std of the heading's change per frame
    attraction: float = 0.2  # share of the turn towards the nearest animal at a burst (0: none)
    rest_rate: float = 0.0015  # chance per frame that a swimming animal starts a rest
    rest_frames: float = 60.0  # mean length of a rest; each lasts 0.5-1.5 × this
    # image
    background_level: float = 185.0  # grey level of the lit floor at the centre
    light_drift: float = 0.03  # amplitude of the slow brightness change (period 20 s), share of the level
    vignetting: float = 0.08  # darkening at the image corners, share of the level
    floor_texture: float = 1.5  # std of the floor's static blotches, grey levels (0: a flat floor)
    blur_px: float = 1.0  # std of the Gaussian blur of the animals (0: none)
    noise_level: float = 1.5  # std of the pixel noise, grey levels (0: none)

    def __post_init__(self) -> None:
        if self.n_animals < 1 or self.frames < 1 or self.image_px < 64:
            raise ValueError("ArenaConfig: n_animals and frames must be >= 1 and image_px >= 64")
        if self.shape not in ARENA_SHAPES:
            raise ValueError(f"ArenaConfig: shape must be one of {', '.join(ARENA_SHAPES)}, got {self.shape!r}")
        if not 0 <= self.size_spread < 0.5 or self.body_length_px <= 0 or self.body_width_px <= 0:
            raise ValueError("ArenaConfig: body sizes must be > 0 and size_spread in [0, 0.5)")
        if self.wall_px < 2 * self.body_length_px:
            raise ValueError(f"ArenaConfig: the arena ({self.wall_px:g} px) is too small for {self.body_length_px:g} "
                             "px animals")

    @property
    def wall_px(self) -> float:
        """Half the arena's width: its radius, or half the side of a square arena."""
        return self.image_px / 2 - self.margin_px


@dataclass(frozen=True)
class Traits:
    """Each animal's individual look, ``(n,)`` arrays: ``scale`` (× the mean body size), ``head`` (extra absorption
    of the head), ``band_at`` (the band's place along the body, 0 = tail tip, 1 = head tip)."""

    scale: np.ndarray
    head: np.ndarray
    band_at: np.ndarray


def draw_traits(config: ArenaConfig, rng: np.random.Generator) -> Traits:
    """Individual differences of ``config.n_animals`` animals."""
    n = config.n_animals
    return Traits(scale=1 + config.size_spread * rng.uniform(-1, 1, n),
                  head=config.head_darkness * rng.uniform(0.5, 1.5, n),
                  band_at=rng.uniform(0.3, 0.7, n))


def _walls(config: ArenaConfig, xy: np.ndarray, heading: np.ndarray,
           limit: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Centres ``xy (n, 2)`` (px from the arena centre) put back within ``limit (n,)`` of the centre (a round arena)
    or of each axis (a square one), and the headings of those that crossed reflected off the wall."""
    step = np.column_stack([np.cos(heading), np.sin(heading)])
    if config.shape == "round":
        r = np.linalg.norm(xy, axis=1)
        out = r > limit
        inward = -xy / np.maximum(r, 1e-9)[:, None]
        dot = np.minimum(np.sum(step * inward, axis=1), 0)
        step = np.where(out[:, None], step - 2 * dot[:, None] * inward, step)
        xy = np.where(out[:, None], -inward * limit[:, None], xy)
    else:
        out_axis = np.abs(xy) > limit[:, None]
        step = np.where(out_axis, -np.sign(xy) * np.abs(step), step)
        xy = np.clip(xy, -limit[:, None], limit[:, None])
    return xy, np.arctan2(step[:, 1], step[:, 0])


def _nearest_bearing(xy: np.ndarray, heading: np.ndarray, reach_px: np.ndarray) -> np.ndarray:
    """Turn (rad, wrapped) from each heading towards the nearest other animal farther than ``reach_px`` (0 when the
    nearest is within reach, or alone)."""
    n = len(xy)
    if n < 2:
        return np.zeros(n)
    d = xy[None, :, :] - xy[:, None, :]
    dist = np.linalg.norm(d, axis=2)
    np.fill_diagonal(dist, np.inf)
    j = np.argmin(dist, axis=1)
    near = d[np.arange(n), j]
    turn = np.arctan2(near[:, 1], near[:, 0]) - heading
    turn = (turn + np.pi) % (2 * np.pi) - np.pi
    return np.where(dist[np.arange(n), j] > reach_px, turn, 0.0)


def simulate_motion(config: ArenaConfig, traits: Traits, rng: np.random.Generator) -> np.ndarray:
    """Truth rows ``(frames × n, 6)`` (see the module docstring), frame-major.

    Each animal swims in bursts: at a burst its speed jumps and it turns, partly towards the nearest other animal when
    that one is more than a body length away; between bursts the speed decays. Swimming animals sometimes rest (still)
    for a while. At the wall an animal's heading is reflected and it is put back inside."""
    n, c = config.n_animals, config.image_px / 2
    length = config.body_length_px * traits.scale
    inside = config.wall_px - length / 2  # centre distance from the arena centre, at most
    if config.shape == "round":
        at = rng.uniform(-np.pi, np.pi, n)
        xy = (inside * np.sqrt(rng.random(n)))[:, None] * np.column_stack([np.cos(at), np.sin(at)])
    else:
        xy = rng.uniform(-1, 1, (n, 2)) * inside[:, None]
    heading = rng.uniform(-np.pi, np.pi, n)
    burst = config.speed_px * (1 - config.glide_decay) / max(config.burst_rate, 1e-9)
    speed = rng.uniform(0, 2, n) * config.speed_px
    rest = np.zeros(n)
    out = np.zeros((config.frames, n, 6))
    for f in range(config.frames):
        out[f, :, 0], out[f, :, 1] = f + 1, np.arange(1, n + 1)
        out[f, :, 2:4], out[f, :, 4], out[f, :, 5] = xy + c, heading, length
        resting = rest > 0
        rest = np.where(resting, rest - 1, 0)
        start = ~resting & (rng.random(n) < config.rest_rate)
        rest[start] = config.rest_frames * rng.uniform(0.5, 1.5, int(start.sum()))
        kick = (rest <= 0) & (rng.random(n) < config.burst_rate)
        toward = config.attraction * _nearest_bearing(xy, heading, length)
        heading = heading + np.where(kick, rng.normal(0, config.turn_rad, n) + toward, 0.0)
        heading = heading + np.where(rest > 0, 0.0, rng.normal(0, config.wiggle_rad, n))
        speed = speed * config.glide_decay * np.where(rest > 0, 0.7, 1.0)  # resting animals stop within frames
        speed = speed + np.where(kick, burst * rng.lognormal(0, 0.3, n), 0.0)
        xy = xy + speed[:, None] * np.column_stack([np.cos(heading), np.sin(heading)])
        xy, heading = _walls(config, xy, heading, inside)
    return out.reshape(-1, 6)


def contact_events(truth: np.ndarray, n_animals: int) -> int:
    """Number of contacts: a pair of animals whose centres come closer than their mean body length, counted once
    per approach (the frame the pair comes within reach, or the first frame when it starts within reach)."""
    t = truth.reshape(-1, n_animals, 6)
    xy, length = t[:, :, 2:4], t[:, :, 5]
    dist = np.linalg.norm(xy[:, :, None, :] - xy[:, None, :, :], axis=3)
    close = dist < (length[:, :, None] + length[:, None, :]) / 2
    iu = np.triu_indices(n_animals, 1)
    pairs = close[:, iu[0], iu[1]]  # (frames, pairs)
    starts = pairs[0].sum() + (pairs[1:] & ~pairs[:-1]).sum()
    return int(starts)
