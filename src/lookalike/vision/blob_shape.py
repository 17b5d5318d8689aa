"""What a blob looks like, as a fixed-length vector that does not depend on where the animal is or which way it
points: its size and shape, how dark it is and in which colour, and how its width and darkness run along its body
axis (the body turned to one reference direction by its principal axis, the thin end first). The offline closed
set learns from these which animal is which (:mod:`lookalike.trackers.offline.appearance`)."""

from __future__ import annotations

import warnings

import numpy as np

from lookalike._optional import needs
from lookalike.parallel import one_blas_thread

__all__ = ["PART_AREA", "PART_COUNTS", "PART_SIZE", "PART_WINDOW", "PROFILE_BINS", "SHAPE_SIZE", "blob_part_vectors",
           "blob_parts", "blob_shapes"]

PROFILE_BINS = 8  # bins of the width and darkness profiles along the body axis
SHAPE_SIZE = 7 + 2 * PROFILE_BINS
"""Length of a blob's vector: log area (px²), log major and minor axis (px), mean difference from the background
(grey levels), mean B, G, R (grey levels), the width profile (fraction of the area per bin) and the darkness profile
(each bin's mean difference over the blob's mean), both from the thin end."""


def blob_shapes(labels: np.ndarray, stats: np.ndarray, keep: list[int], difference: np.ndarray,
                image: np.ndarray) -> np.ndarray:
    """``(len(keep), SHAPE_SIZE)`` vectors of the connected components ``keep`` of ``labels`` (from
    ``cv2.connectedComponentsWithStats``, with its ``stats``); ``difference``: ``(h, w)`` difference from the
    background; ``image``: the ``(h, w, 3)`` BGR frame."""
    out = np.zeros((len(keep), SHAPE_SIZE))
    for row, k in enumerate(keep):
        x, y, w, h = (int(v) for v in stats[k, :4])
        mask = labels[y:y + h, x:x + w] == k
        ys, xs = np.nonzero(mask)
        weight = difference[y:y + h, x:x + w][mask].astype(float)
        colour = image[y:y + h, x:x + w][mask].astype(float)
        out[row] = _shape(xs.astype(float), ys.astype(float), weight, colour)
    return out


def _shape(xs: np.ndarray, ys: np.ndarray, weight: np.ndarray, colour: np.ndarray) -> np.ndarray:
    area = len(xs)  # (means as sum / count: numpy's mean, without its per-call overhead)
    pts = np.column_stack([xs - xs.sum() / area, ys - ys.sum() / area])
    cov = pts.T @ pts / max(area, 1) + np.eye(2) / 12  # (a pixel's own spread: single-pixel blobs stay finite)
    values, vectors = np.linalg.eigh(cov)
    along = pts @ vectors[:, 1]
    if np.sum(along**3) > 0:  # the thin end first: the long thin end (a tail) runs to negative values
        along = -along
    half = 2 * np.sqrt(values[1])  # half the major axis (px)
    bins = np.clip(((along / half + 1.25) / 2.5 * PROFILE_BINS).astype(int), 0, PROFILE_BINS - 1)
    counts = np.bincount(bins, minlength=PROFILE_BINS).astype(float)
    dark = np.bincount(bins, weights=weight, minlength=PROFILE_BINS)
    mean_dark = float(weight.sum() / area) if area else 0.0
    profile = np.where(counts > 0, dark / np.maximum(counts, 1) / max(mean_dark, 1e-6), 0.0)
    colour_mean = colour.sum(axis=0) / area if area else np.zeros(3)
    return np.concatenate([[np.log(max(area, 1)), np.log(4 * np.sqrt(values[1])), np.log(4 * np.sqrt(values[0])),
                            mean_dark], colour_mean, counts / max(area, 1), profile])


PART_COUNTS = (2, 3)  # the splits of a blob that may hold several animals
PART_SIZE = 2 * sum(PART_COUNTS)
"""Length of a blob's parts vector: the centroids ``x, y`` (px, image frame) of its 2-part split, then of its 3-part."""
PART_AREA = 1.4  # a blob is split when its area is at least this many times the median of the recent blobs'
PART_WINDOW = 512  # the recent blobs: this many, the current frame's included
MIXTURE_PIXELS = 4000  # a larger blob's mixture is fitted on a regular grid of its pixels, about this many (work)


def blob_part_vectors(labels: np.ndarray, stats: np.ndarray, keep: list[int], reference_area: float) -> np.ndarray:
    """``(len(keep), PART_SIZE)`` :func:`blob_parts` vectors of the components ``keep`` of ``labels`` (as
    :func:`blob_shapes`) whose area is at least :data:`PART_AREA` times ``reference_area`` (px²); NaN for the others."""
    out = np.full((len(keep), PART_SIZE), np.nan)
    split = [(row, k) for row, k in enumerate(keep) if stats[k, 4] >= PART_AREA * reference_area]
    if split:
        with one_blas_thread():  # (the mixtures' 2 x 2 solves: a BLAS pool's hand-offs cost more than the work)
            for row, k in split:
                x, y, w, h = (int(v) for v in stats[k, :4])
                ys, xs = np.nonzero(labels[y:y + h, x:x + w] == k)
                out[row] = blob_parts(xs + x, ys + y)
    return out


def blob_parts(xs: np.ndarray, ys: np.ndarray, iterations: int = 8) -> np.ndarray:
    """The :data:`PART_SIZE` vector of the pixels ``xs, ys`` (px) of one blob: for each count k in
    :data:`PART_COUNTS`, the means of a Gaussian mixture with k full-covariance components (:func:`_mixture`),
    started from each of two k-means splits of the pixel coordinates (started evenly along the major and along the
    minor principal axis), the more likely mixture kept (the major axis's on ties; where neither can be fitted, the
    k-means split with the smaller within-part spread), ordered along the major axis."""
    pts = np.column_stack([xs, ys]).astype(float)
    centre = pts.mean(axis=0)
    cov = np.cov((pts - centre).T) if len(pts) > 1 else np.eye(2)
    values, vectors = np.linalg.eigh(cov + np.eye(2) / 12)
    out = []
    for k in PART_COUNTS:
        best, best_cost = np.repeat(centre[None], k, axis=0), np.inf
        fitted, fitted_score = None, -np.inf
        for axis in (1, 0):
            offsets = np.linspace(-1.0, 1.0, k) * np.sqrt(values[axis])
            centres = centre + offsets[:, None] * vectors[:, axis]
            previous = None
            for _ in range(iterations):
                label = np.argmin(((pts[:, None] - centres[None]) ** 2).sum(axis=2), axis=1)
                if previous is not None and np.array_equal(label, previous):
                    break  # converged: more rounds would give the same parts
                previous = label
                counts = np.bincount(label, minlength=k)
                if np.any(counts == 0):
                    break
                centres = np.column_stack([np.bincount(label, weights=pts[:, d], minlength=k) for d in (0, 1)]) \
                    / counts[:, None]
            if not np.all(counts > 0):
                continue
            cost = float(((pts - centres[label]) ** 2).sum())
            if cost < best_cost:
                best, best_cost = centres, cost
            mixture = _mixture(pts, label, k, centres)
            if mixture is not None and mixture[1] > fitted_score:
                fitted, fitted_score = mixture
        if fitted is not None:
            best = fitted
        out.append(best[np.argsort(best @ vectors[:, 1])])
    return np.concatenate([c.ravel() for c in out])


def _mixture(pts: np.ndarray, label: np.ndarray, k: int, centres: np.ndarray) -> tuple[np.ndarray, float] | None:
    """``((k, 2) means (px), mean log-likelihood of the pixels fitted)`` of sklearn's full-covariance Gaussian mixture
    of ``pts`` started from the split ``label`` (its parts' shares, ``centres`` and pixel covariances plus 1/12 px² of
    pixel quantisation); None where a part has fewer than 3 pixels or the mixture cannot be fitted. A blob of more
    than :data:`MIXTURE_PIXELS` pixels is fitted on those on every s-th row and column (s the smallest step leaving at
    most about that many). k-means shares the pixels of long thin animals in a T or a V evenly between the parts, and
    cuts two lying side by side into front and back halves; elongated components follow the bodies (from the split
    across them, for the side by side)."""
    with needs("sklearn"):
        from sklearn.exceptions import ConvergenceWarning
        from sklearn.mixture import GaussianMixture

    step = int(np.ceil(np.sqrt(len(pts) / MIXTURE_PIXELS)))
    if step > 1:  # a large blob: the pixels on every step-th row and column
        on = np.all(pts % step == 0, axis=1)
        pts, label = pts[on], label[on]
    counts = np.bincount(label, minlength=k)
    if np.any(counts < 3):
        return None
    precisions = np.array([np.linalg.inv(np.cov(pts[label == j].T) + np.eye(2) / 12) for j in range(k)])
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", ConvergenceWarning)  # (the means after the iteration cap are kept)
            mixture = GaussianMixture(k, covariance_type="full", weights_init=counts / len(pts), means_init=centres,
                                      precisions_init=precisions, init_params="random", random_state=0).fit(pts)
            return np.asarray(mixture.means_, dtype=float), float(mixture.score(pts))
    except (ValueError, np.linalg.LinAlgError):
        return None
