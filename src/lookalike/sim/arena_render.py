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
_AA_PX = 0.5  # how far anti-aliased filling reaches outside a polygon, px
_NOISE_SHIFTS = 64  # offsets of the noise bank per axis: frames draw their noise from 64² crops of one bank
_BLOTCH_PX = 8.0  # size (Gaussian std) of the floor texture's blotches


def _profile(width_share: float, samples: int = 24) -> tuple[np.ndarray, np.ndarray]:
    """The body's half-width profile in body lengths: places ``q (samples,)`` from the tail tip (0) to the head tip
    (1) and half-widths ``h (samples,)``: a rounded front and a tapering tail."""
    q = np.linspace(0, 1, samples)
    front = 0.62
    h = np.where(q >= front, np.sqrt(np.clip(1 - ((q - front) / (1 - front)) ** 2, 0, 1)),
                 0.1 + 0.9 * (q / front) ** 1.3) * width_share / 2
    h[-1] = 0.0
    return q, h


def _bent(q: np.ndarray, h: np.ndarray, bend: np.ndarray) -> np.ndarray:
    """Closed outlines ``(r, 2 m, 2)`` in body lengths (head tip at 0, heading along +x) of the body part at places
    ``q (m,)`` with half-widths ``h (m,)``, its midline a circular arc that turns by ``bend (r,)`` rad from head to
    tail."""
    s = 1 - q[None, :]  # arc length from the head tip
    b = bend[:, None]
    straight = np.abs(b) < 1e-6
    safe = np.where(straight, 1.0, b)
    mid = -np.stack([np.where(straight, s, np.sin(b * s) / safe),
                     np.where(straight, b * s ** 2 / 2, (1 - np.cos(b * s)) / safe)], axis=2)
    normal = np.stack([-np.sin(b * s), np.cos(b * s)], axis=2)
    upper, lower = mid + h[None, :, None] * normal, mid - h[None, :, None] * normal
    return np.concatenate([upper, lower[:, ::-1]], axis=1)


def _centroid(polygons: np.ndarray) -> np.ndarray:
    """Area centroids ``(r, 2)`` of closed polygons ``(r, m, 2)``."""
    x, y = polygons[..., 0], polygons[..., 1]
    x1, y1 = np.roll(x, -1, axis=1), np.roll(y, -1, axis=1)
    cross = x * y1 - x1 * y
    area = cross.sum(axis=1) * 3
    return np.stack([((x + x1) * cross).sum(axis=1), ((y + y1) * cross).sum(axis=1)], axis=1) / area[:, None]


def _place(local: np.ndarray, centroid: np.ndarray, rows: np.ndarray) -> np.ndarray:
    """Outlines ``local (r, m, 2)`` (body lengths) moved into the image (px) so that ``centroid (r, 2)`` lands on
    each truth row's centre, turned to its heading and scaled to its length."""
    c, s = np.cos(rows[:, 4])[:, None], np.sin(rows[:, 4])[:, None]
    d = (local - centroid[:, None, :]) * rows[:, 5, None, None]
    return rows[:, None, 2:4] + np.stack([c * d[..., 0] - s * d[..., 1], s * d[..., 0] + c * d[..., 1]], axis=2)


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

    @cached_property
    def bend(self) -> np.ndarray:
        """Each truth row's body bend ``(frames × n,)`` rad: ``body_bend`` × the heading's change over the last 3
        frames (the tail trails the turn), within ±1.2 rad."""
        t = self.truth.reshape(self.config.frames, self.config.n_animals, 6)[:, :, 4]
        before = t[np.maximum(np.arange(len(t)) - 3, 0)]
        turn = (t - before + np.pi) % (2 * np.pi) - np.pi
        return np.clip(-self.config.body_bend * turn, -1.2, 1.2).ravel()

    def _outlines(self, rows: slice) -> tuple[np.ndarray, np.ndarray]:
        """The whole silhouettes ``(r, m, 2)`` px of the truth ``rows`` and their centroids in body lengths."""
        cfg = self.config
        q, h = _profile(cfg.body_width_px / cfg.body_length_px)
        local = _bent(q, h, self.bend[rows])
        centroid = _centroid(local)
        return _place(local, centroid, self.truth[rows]), centroid

    def _shapes(self, k: int) -> list[tuple[np.ndarray, float]]:
        """The polygons (px) of frame ``k`` and their absorption, to fill in order: per animal body, band, head.

        The polygons are narrower than the silhouette by :data:`_AA_PX` on each side: anti-aliased filling widens
        them by as much, so the drawn silhouette's centroid is the truth's centre."""
        cfg, n = self.config, self.config.n_animals
        rows = slice((k - 1) * n, k * n)
        truth, bend = self.truth[rows], self.bend[rows]
        _, centroid = self._outlines(rows)
        q, h = _profile(cfg.body_width_px / cfg.body_length_px)
        out = []
        for i in range(n):
            spans = [(0.0, 1.0, cfg.body_darkness)]
            if cfg.pattern_darkness > 0:
                at = self.traits.band_at[i]
                spans.append((at - _BAND_HALF, at + _BAND_HALF, cfg.body_darkness + cfg.pattern_darkness))
            if self.traits.head[i] > 0:
                spans.append((_HEAD_FROM, 1.0, cfg.body_darkness + self.traits.head[i]))
            for lo, hi, dark in spans:
                qs = np.concatenate([[lo], q[(q > lo) & (q < hi)], [hi]])
                hs = np.maximum(np.interp(qs, q, h) - _AA_PX / truth[i, 5], 0)
                local = _bent(qs, hs, bend[i:i + 1])
                out.append((_place(local, centroid[i:i + 1], truth[i:i + 1])[0], min(dark, 1.0)))
        return out

    def boxes(self) -> np.ndarray:
        """Each truth row's axis-aligned bounding box of the silhouette, ``(frames × n, 4)`` xywh px."""
        pts, _ = self._outlines(slice(None))
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
        for poly, dark in self._shapes(k):
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
