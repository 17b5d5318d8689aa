"""Rendered arenas: :func:`simulate_arena` moves look-alike animals (:mod:`lookalike.sim.arena`) and
:class:`Arena` draws any frame of them as a grey BGR image, with lighting drift, vignetting, blur and noise."""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass
from functools import cached_property

import numpy as np

from lookalike._optional import needs
from lookalike.sim.arena import ArenaConfig, Traits, contact_events, draw_traits, simulate_motion

_LIGHT_PERIOD_S = 20.0  # period of the lighting drift, seconds
_HEAD_FROM = 0.8  # the head: from this place along the body (0 = tail tip, 1 = head tip)
_BAND_HALF = 0.04  # half the band's width along the body, share of the length
_SUBPIXEL = 4  # fractional bits of the drawn polygons' vertices
_NOISE_SHIFTS = 64  # offsets of the noise bank per axis: frames draw their noise from 64² crops of one bank
_BLOTCH_PX = 8.0  # size (Gaussian std) of the floor texture's blotches


def _outline(width_share: float, samples: int = 20) -> tuple[np.ndarray, np.ndarray]:
    """The body's half-width profile in body lengths: places ``x (samples,)`` from the tail tip (0) to the head tip
    (1), shifted so that the silhouette's centroid is at 0, and half-widths ``h (samples,)``: a rounded front and a
    tapering tail."""
    x = np.linspace(0, 1, samples)
    front = 0.62
    h = np.where(x >= front, np.sqrt(np.clip(1 - ((x - front) / (1 - front)) ** 2, 0, 1)),
                 0.1 + 0.9 * (x / front) ** 1.3) * width_share / 2
    h[-1] = 0.0
    centroid = float(np.trapezoid(x * h, x) / np.trapezoid(h, x))
    return x - centroid, h


def _strip(x: np.ndarray, h: np.ndarray, lo: float, hi: float) -> tuple[np.ndarray, np.ndarray]:
    """The closed outline (body units, ``(m, 2)``) of the part of the body between places ``lo`` and ``hi``."""
    keep = (x >= lo) & (x <= hi)
    xs = np.concatenate([[lo], x[keep], [hi]])
    hs = np.interp(xs, x, h)
    return xs, hs


@dataclass(frozen=True, eq=False)
class Arena:
    """A simulated arena: ``truth (frames × n, 6)`` rows (see :mod:`lookalike.sim.arena`), each animal's
    :class:`~lookalike.sim.arena.Traits`, and the ``config`` and ``seed`` that made them. ``frame(k)`` draws frame
    ``k`` (1-based); the same arena draws the same pixels every time."""

    config: ArenaConfig
    seed: int
    truth: np.ndarray
    traits: Traits

    @property
    def contacts(self) -> int:
        """Contacts (:func:`lookalike.sim.arena.contact_events`)."""
        return contact_events(self.truth, self.config.n_animals)

    def _shapes(self, k: int) -> list[list[tuple[np.ndarray, float]]]:
        """Per animal of frame ``k``: ``(polygon (m, 2) px, absorption)`` to fill in order (body, band, head)."""
        cfg, n = self.config, self.config.n_animals
        rows = self.truth[(k - 1) * n:k * n]
        x, h = _outline(cfg.body_width_px / cfg.body_length_px)
        tip = x[-1]
        out = []
        for i, (_, _, cx, cy, heading, length) in enumerate(rows):
            u, v = np.array([np.cos(heading), np.sin(heading)]), np.array([-np.sin(heading), np.cos(heading)])
            shapes = []
            spans = [(x[0], tip, cfg.body_darkness)]
            if cfg.pattern_darkness > 0:
                at = x[0] + self.traits.band_at[i]
                spans.append((at - _BAND_HALF, at + _BAND_HALF, cfg.body_darkness + cfg.pattern_darkness))
            if self.traits.head[i] > 0:
                spans.append((x[0] + _HEAD_FROM, tip, cfg.body_darkness + self.traits.head[i]))
            for lo, hi, dark in spans:
                xs, hs = _strip(x, h, lo, hi)
                side = np.concatenate([hs, -hs[::-1]]) * length
                along = np.concatenate([xs, xs[::-1]]) * length
                poly = np.array([cx, cy]) + along[:, None] * u + side[:, None] * v
                shapes.append((poly, min(dark, 1.0)))
            out.append(shapes)
        return out

    def boxes(self) -> np.ndarray:
        """Each truth row's axis-aligned bounding box of the silhouette, ``(frames × n, 4)`` xywh px."""
        cfg = self.config
        x, h = _outline(cfg.body_width_px / cfg.body_length_px)
        t = self.truth
        u = np.stack([np.cos(t[:, 4]), np.sin(t[:, 4])], axis=1)
        v = np.stack([-u[:, 1], u[:, 0]], axis=1)
        along = np.concatenate([x, x[::-1]])[None, :, None] * t[:, 5, None, None]
        side = np.concatenate([h, -h[::-1]])[None, :, None] * t[:, 5, None, None]
        pts = t[:, None, 2:4] + along * u[:, None, :] + side * v[:, None, :]
        lo, hi = pts.min(axis=1), pts.max(axis=1)
        return np.hstack([lo, hi - lo])

    def frame(self, k: int) -> np.ndarray:
        """Frame ``k`` (1-based) as a uint8 BGR image ``(image_px, image_px, 3)``."""
        with needs("cv2"):
            import cv2

        cfg = self.config
        if not 1 <= k <= cfg.frames:
            raise ValueError(f"frame {k} is outside 1..{cfg.frames}")
        side = cfg.image_px
        absorb: np.ndarray = np.zeros((side, side), np.uint8)
        for shapes in self._shapes(k):
            for poly, dark in shapes:
                pts = np.round(poly * (1 << _SUBPIXEL)).astype(np.int32)
                cv2.fillPoly(absorb, [pts], round(255 * dark), cv2.LINE_AA, _SUBPIXEL)
        if cfg.blur_px > 0:
            absorb = cv2.GaussianBlur(absorb, (0, 0), cfg.blur_px)
        floor, noise, phase = self._floor
        level = cfg.background_level * (1 + cfg.light_drift * np.sin(
            2 * np.pi * (k - 1) / (_LIGHT_PERIOD_S * cfg.frame_rate_hz) + phase))
        transmit = cv2.LUT(absorb, (1 - np.arange(256, dtype=np.float32) / 255) * np.float32(level))
        image = cv2.multiply(floor, transmit)
        dx, dy = np.random.default_rng([self.seed, k]).integers(0, _NOISE_SHIFTS, 2)
        image += noise[dy:dy + side, dx:dx + side]
        grey = np.clip(image, 0, 255, out=image).astype(np.uint8)
        return cv2.cvtColor(grey, cv2.COLOR_GRAY2BGR)

    @cached_property
    def _floor(self) -> tuple[np.ndarray, np.ndarray, float]:
        """The static floor (relative lighting with vignetting and texture, ``(side, side)`` float32), a bank of
        pixel noise that each frame crops at its own offset (+0.5 to round), and the phase of the lighting drift."""
        with needs("cv2"):
            import cv2

        cfg, side = self.config, self.config.image_px
        rng = np.random.default_rng([self.seed, 0])
        phase = float(rng.uniform(0, 2 * np.pi))
        r = np.linspace(-1, 1, side, dtype=np.float32)
        floor = 1 - np.float32(cfg.vignetting) * (r[None, :] ** 2 + r[:, None] ** 2) / 2
        if cfg.floor_texture > 0:
            blotches = cv2.GaussianBlur(rng.standard_normal((side, side), dtype=np.float32), (0, 0), _BLOTCH_PX)
            floor += blotches * np.float32(cfg.floor_texture / cfg.background_level / blotches.std())
        noise = rng.standard_normal((side + _NOISE_SHIFTS,) * 2, dtype=np.float32) * np.float32(cfg.noise_level)
        return floor.astype(np.float32), noise + np.float32(0.5), phase

    def frames(self) -> Iterator[np.ndarray]:
        """Every frame in order (:meth:`frame`)."""
        for k in range(1, self.config.frames + 1):
            yield self.frame(k)


def simulate_arena(config: ArenaConfig | None = None, seed: int = 0) -> Arena:
    """An arena of ``config`` (default: the documented difficulty), the same for the same ``seed``."""
    cfg = config or ArenaConfig()
    rng = np.random.default_rng(seed)
    traits = draw_traits(cfg, rng)
    return Arena(cfg, seed, simulate_motion(cfg, traits, rng), traits)


__all__ = ["Arena", "simulate_arena"]
