"""Identity evidence learned from one video's own blobs, without labels, for the offline closed set.

Each input row carries its blob's shape vector (:mod:`lookalike.vision.blob_shape`). A row shows one animal when its
area is near its track's typical blob's (:func:`single_rows`); tracklets are cut where that changes, so the rows of
merged blobs form pieces of their own (:func:`cut_at_merges`). From the single-animal tracklets,
:func:`fit_identity_space` learns a linear map in which rows of one tracklet lie close together and the mean looks of
tracklets alive at the same time (so certainly different animals) lie far apart: Fisher's discriminant with the
within-tracklet scatter against the scatter between concurrent pairs. :meth:`IdentitySpace.link_evidence` then says,
for pairs of tracklets, how much more likely their looks are if each pair is one animal than if it is two: a
log-likelihood ratio of the log distance between the two mean looks, calibrated on the same video. "Two animals" is
the distribution of the concurrent pairs' distances; "one animal" is the other part of a two-part mixture fitted to
the distances of the candidate links themselves (a look changes more across a crossing than within a tracklet)"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from lookalike.trackers.offline.tracklets import Tracklet

__all__ = ["IdentitySpace", "cut_at_merges", "fit_identity_space", "log_distance", "look_margin", "look_margins",
           "single_rows", "with_appearance"]

SINGLE_AREA = (0.6, 1.5)  # a blob shows one animal when its area is within these multiples of its track's median
MIN_ROWS = 8  # single-animal rows a tracklet needs to teach or be judged by its look
OUTLIER = 0.001  # chance that a tracklet's look is not its animal's (a bad segmentation): bounds a link's evidence
LOOK_WEIGHT = 2.0  # a link's cost is lowered by this times its look's log-likelihood ratio (rule7.md in research/)
SHAPE_COLUMN = 9  # the column of an input row that holds its shape vector's index
MIN_SPREAD = 0.1  # smallest spread of a log look distance (a floor for the fits on few pairs)
MARGIN_CLIP = 3.0  # bound of a tracklet's look margin (log distance ratio; look_margins)
UNTRUSTED_SHARE = 0.135  # more of the online pass's rows not one animal's size: no look (research/appearance/rule4.md)


def single_rows(rows: np.ndarray, shapes: np.ndarray) -> np.ndarray:
    """Mask of the input ``rows`` (column 9 indexing ``shapes``, ``(k, SHAPE_SIZE)``) whose blob area is that of one
    animal: within :data:`SINGLE_AREA` of the median area of the rows of the same input id."""
    area = np.exp(shapes[rows[:, SHAPE_COLUMN].astype(int), 0])
    order = np.argsort(rows[:, 1], kind="stable")
    starts = np.flatnonzero(np.r_[True, np.diff(rows[order, 1]) != 0])
    medians = [np.median(block) for block in np.split(area[order], starts[1:])] if len(rows) else []
    typical = np.empty_like(area)
    typical[order] = np.repeat(medians, np.diff(np.r_[starts, len(rows)])) if len(rows) else area
    mask: np.ndarray = (area >= SINGLE_AREA[0] * typical) & (area <= SINGLE_AREA[1] * typical)
    return mask


def cut_at_merges(tracklets: list[Tracklet], shapes: np.ndarray) -> tuple[list[Tracklet], list[Tracklet]]:
    """``tracklets`` cut where their rows go from one animal's blob to a merged one and back (:func:`single_rows`
    over all their rows); returns the single-animal pieces and the others."""
    alone: list[Tracklet] = []
    merged: list[Tracklet] = []
    if not tracklets:
        return alone, merged
    single = single_rows(np.vstack([t.rows for t in tracklets]), shapes)
    flags = np.split(single, np.cumsum([len(t) for t in tracklets])[:-1])
    for t, flag in zip(tracklets, flags):
        for piece in np.split(np.arange(len(t)), np.flatnonzero(np.diff(flag.astype(int))) + 1):
            part = Tracklet(t.rows[piece], t.source_id, t.contact or not flag[piece[0]])
            (alone if flag[piece[0]] else merged).append(part)
    alone.sort(key=lambda t: (t.first, t.last))
    return alone, merged


@dataclass(frozen=True)
class IdentitySpace:
    """A learned identity map: shape vectors ``x`` go to ``(x - mean) / scale @ projection``; ``other`` is the mean
    and spread of the log per-dimension squared distance between the mean looks of two concurrent animals."""

    mean: np.ndarray
    scale: np.ndarray
    projection: np.ndarray
    other: tuple[float, float]

    def embed(self, shapes: np.ndarray) -> np.ndarray:
        """Identity coordinates ``(k, d)`` of shape vectors ``(k, SHAPE_SIZE)``."""
        out: np.ndarray = ((shapes - self.mean) / self.scale) @ self.projection
        return out

    def link_evidence(self, a: np.ndarray, b: np.ndarray) -> np.ndarray:
        """Log-likelihood ratios, one animal against two, of the pairs of mean looks ``a[k], b[k]`` (``(k, d)``).

        Each pair's statistic is its log mean squared coordinate difference, normal under either hypothesis; "two" is
        :attr:`other`, "one" is fitted to these pairs (mixture, :func:`_fit_same`). Distances below the "one"
        mean count as that mean, above the "two" mean as that mean (the ratio never grows with the distance). Either
        look is its animal's but with probability :data:`OUTLIER`, so each ratio stays within ±ln(1/OUTLIER)."""
        x = log_distance(a, b)
        same = _fit_same(x, self.other)
        log_same = _log_normal(np.maximum(x, same[0]), same)
        log_other = _log_normal(np.minimum(x, self.other[0]), self.other)
        odds = np.exp(np.clip(log_same - log_other, -50.0, 50.0))
        out: np.ndarray = np.log(((1 - OUTLIER) * odds + OUTLIER) / ((1 - OUTLIER) + OUTLIER * odds))
        return out


def log_distance(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """The log mean squared difference of looks ``a`` and ``b`` along their last axis (broadcast)."""
    out: np.ndarray = np.log(np.mean((a - b) ** 2, axis=-1) + 1e-9)
    return out


def look_margin(mine: np.ndarray, own: np.ndarray, others: np.ndarray) -> float:
    """How much better the look ``own`` fits the look ``mine`` (``(d,)``) than the nearest of ``others``
    (``(m, d)``): the difference of their :func:`log_distance`, within ±:data:`MARGIN_CLIP`."""
    return float(np.clip(log_distance(mine, others).min() - log_distance(mine, own), -MARGIN_CLIP, MARGIN_CLIP))


def _log_normal(x: np.ndarray, normal: tuple[float, float]) -> np.ndarray:
    out: np.ndarray = -0.5 * ((x - normal[0]) / normal[1]) ** 2 - math.log(normal[1])
    return out


def _fit_same(x: np.ndarray, other: tuple[float, float], iterations: int = 100) -> tuple[float, float]:
    """Mean and spread of the "one animal" part of a two-part normal mixture of ``x``, the other part fixed at
    ``other`` (expectation-maximisation from the lowest tenth of ``x``)."""
    mean, spread, weight = float(np.percentile(x, 10)), other[1], 0.5
    for _ in range(iterations):
        p_same = weight * np.exp(_log_normal(x, (mean, spread)))
        p_other = (1 - weight) * np.exp(_log_normal(x, other))
        g = p_same / (p_same + p_other + 1e-300)
        if g.sum() < 1e-6:
            break
        weight = float(g.mean())
        mean = float(g @ x / g.sum())
        spread = max(math.sqrt(float(g @ (x - mean) ** 2 / g.sum())), MIN_SPREAD)
    return min(mean, other[0]), spread


def _concurrent_pairs(first: np.ndarray, last: np.ndarray) -> list[tuple[int, int]]:
    """Pairs ``(i, j)``, ``i < j``, of frame spans ``[first, last]`` that share a frame (a sweep over the starts)."""
    order = np.argsort(first, kind="stable")
    starts = first[order]
    pairs = []
    for k, i in enumerate(order.tolist()):
        for j in order[k + 1:np.searchsorted(starts, last[i], side="right")].tolist():
            pairs.append((min(i, j), max(i, j)))
    return sorted(pairs)


def _scatter(groups: list[np.ndarray]) -> np.ndarray:
    centred = np.vstack([g - g.mean(axis=0) for g in groups])
    dof = sum(len(g) - 1 for g in groups)
    out: np.ndarray = centred.T @ centred / max(dof, 1)
    return out


def _generalised_eigh(a: np.ndarray, b: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Ascending eigenvalues and eigenvectors ``V`` of ``a v = λ b v`` (``a`` symmetric, ``b`` symmetric positive
    definite), ``V.T @ b @ V = I``: through ``b``'s Cholesky factor, with numpy alone (importing ``scipy.linalg``
    costs a quarter of a second)."""
    inverse = np.linalg.inv(np.linalg.cholesky(b))
    values, vectors = np.linalg.eigh(inverse @ a @ inverse.T)
    return values, inverse.T @ vectors


def fit_identity_space(tracklets: list[Tracklet], shapes: np.ndarray) -> IdentitySpace | None:
    """The identity map learned from single-animal ``tracklets`` (their rows' column 9 indexes ``shapes``), or None
    when no two tracklets of :data:`MIN_ROWS` rows are alive at once (nothing to tell apart)."""
    long = [t for t in tracklets if len(t) >= MIN_ROWS]
    if len(long) < 2:
        return None
    pairs = _concurrent_pairs(np.array([t.first for t in long]), np.array([t.last for t in long]))
    if not pairs:
        return None
    raw = [shapes[t.rows[:, SHAPE_COLUMN].astype(int)] for t in long]
    every = np.vstack(raw)
    mean, scale = every.mean(axis=0), every.std(axis=0) + 1e-6
    groups = [(x - mean) / scale for x in raw]
    within = _scatter(groups) + 1e-3 * np.eye(every.shape[1])
    means = np.array([g.mean(axis=0) for g in groups])
    diffs = np.array([means[i] - means[j] for i, j in pairs])
    apart = diffs.T @ diffs / len(diffs)
    values, vectors = _generalised_eigh(apart, within)
    keep = values > 1.0  # directions where concurrent animals differ by more than a tracklet's own noise
    if not keep.any():
        return None
    projection = vectors[:, keep]
    looks = [(g @ projection).mean(axis=0) for g in groups]
    x = np.log([np.mean((looks[i] - looks[j]) ** 2) + 1e-9 for i, j in pairs])
    return IdentitySpace(mean, scale, projection, (float(x.mean()), max(float(x.std()), MIN_SPREAD)))


def with_appearance(tracklets: list[Tracklet], links: tuple[np.ndarray, np.ndarray, np.ndarray], shapes: np.ndarray,
                    space: IdentitySpace) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``links`` ``(i, j, cost)`` with each cost lowered by :data:`LOOK_WEIGHT` times
    :meth:`IdentitySpace.link_evidence` of its two tracklets."""
    src, dst, cost = links
    if not len(src):
        return links
    looks = np.array([space.embed(shapes[t.rows[:, SHAPE_COLUMN].astype(int)]).mean(axis=0) for t in tracklets])
    return src, dst, cost - LOOK_WEIGHT * space.link_evidence(looks[src], looks[dst])


def look_margins(tracklets: list[Tracklet], chains: Sequence[Sequence[int]], shapes: np.ndarray,
                 space: IdentitySpace) -> np.ndarray:
    """Per tracklet, how much better its identity's look fits it than any other identity's: the log mean squared
    distance from its mean look to the nearest other identity's mean look minus that to its own identity's (the
    rows-weighted mean of its other tracklets), clipped to ±:data:`MARGIN_CLIP`. ``chains``: each identity's
    tracklet indices. NaN for tracklets of fewer than :data:`MIN_ROWS` rows, on no chain, or with nothing to
    compare (no other tracklet on their identity, or no other identity with one)."""
    out = np.full(len(tracklets), np.nan)
    members = [[int(i) for i in chain if len(tracklets[i]) >= MIN_ROWS] for chain in chains]
    looks = {i: space.embed(shapes[tracklets[i].rows[:, SHAPE_COLUMN].astype(int)]).mean(axis=0)
             for chain in members for i in chain}
    total = [sum((len(tracklets[i]) * looks[i] for i in chain), np.zeros(space.projection.shape[1]))
             for chain in members]
    count = [sum(len(tracklets[i]) for i in chain) for chain in members]
    for c, chain in enumerate(members):
        others = [total[k] / count[k] for k in range(len(members)) if k != c and count[k]]
        for i in chain:
            rest = count[c] - len(tracklets[i])
            if not rest or not others:
                continue
            out[i] = look_margin(looks[i], (total[c] - len(tracklets[i]) * looks[i]) / rest, np.array(others))
    return out
