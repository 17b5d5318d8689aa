"""Which two agents hold each other's robots, from the detections' visual headings gathered over seconds.

After an exchange of ids that the heading reports barely show (two robots heading within a few tenths of a
radian of each other), the network's memory of positions keeps the two agents on the wrong robots. One frame's
visual heading cannot tell them apart (a 10-class heading classifier is off by about 0.28 rad), but many can:
for two agents ``a`` and ``b`` that each hold a detection and have a fresh report, a frame adds to the pair's
evidence the log-likelihood ratio of "a's detection is b's robot and b's is a's" over the labels as they are,
each detection's visual heading modelled as its robot's reported heading plus Gaussian noise ``noise_rad``,
turned front to back with probability ``flip_prob`` and anything at all with probability ``outlier_prob``. A
frame adds at most ``max_step`` either way (both detections seen front to back in one frame would otherwise
add about 7 for two robots heading opposite ways), so an exchange needs consistent evidence over several frames. The
evidence is summed over frames, decays with time constant ``memory_s`` and never drops below zero (a CUSUM), so
that two robots whose headings stay apart keep it at zero; when a pair's passes ``threshold`` the two agents
are said to be exchanged and their evidence starts again. An agent whose report is older than ``fresh_s`` (its robot
silent for a while) takes part too, its robot's heading modelled as its last report with the noise widened by
``stale_rad_s`` radians per second beyond ``fresh_s`` (how far a robot may have turned since): the pair's evidence
then comes mostly from the agent that still reports.
"""

from __future__ import annotations

import numpy as np

MEMORY_S = 10.0  # time constant of the evidence's decay, seconds
NOISE_RAD = 0.28  # a visual heading's noise around its robot's heading (10 classes, 12 degrees of noise), radians
STALE_RAD_S = 0.5  # widening of an older report's noise, radians per second of age beyond fresh_s


def take_pairs(evidence: np.ndarray, threshold: float | np.ndarray) -> list[tuple[int, int]]:
    """The pairs ``(a, b)``, ``a < b``, whose symmetric ``evidence`` passes ``threshold`` (one for all, or one per
    pair), the strongest first and each agent at most once; their rows and columns are cleared in place (their
    evidence starts again)."""
    pairs = []
    while (passing := evidence > threshold).any():
        a, b = np.unravel_index(int(np.argmax(np.where(passing, evidence, -np.inf))), evidence.shape)
        pairs.append((int(min(a, b)), int(max(a, b))))
        evidence[[a, b], :] = 0.0
        evidence[:, [a, b]] = 0.0
    return pairs


class VisualExchange:
    """Exchange detector over ``n`` agents from their detections' visual headings (see the module)."""

    def __init__(self, n: int, threshold: float, memory_s: float = MEMORY_S, noise_rad: float = NOISE_RAD,
                 flip_prob: float = 0.03, outlier_prob: float = 0.02, fresh_s: float = 0.5,
                 max_step: float = 1.5, stale_rad_s: float = STALE_RAD_S) -> None:
        """``threshold``: log-likelihood ratio a pair must pass; ``memory_s``: time constant of the evidence's
        decay, seconds; ``noise_rad``: a visual heading's noise around its robot's heading (standard deviation),
        radians; ``flip_prob``: probability that a visual heading is turned by π; ``outlier_prob``: probability that
        it says nothing of the robot (uniform); ``fresh_s``: only reports younger than this count, seconds;
        ``max_step``: the most one frame adds or takes; ``stale_rad_s``: older reports count with their noise
        widened by this many radians per second beyond ``fresh_s``."""
        if n < 0 or min(threshold, memory_s, noise_rad, max_step, stale_rad_s) <= 0:
            raise ValueError(f"VisualExchange needs n >= 0 and positive threshold, memory_s, noise_rad, max_step and "
                             f"stale_rad_s, "
                             f"got n={n}, threshold={threshold}, memory_s={memory_s}, noise_rad={noise_rad}, "
                             f"max_step={max_step}, stale_rad_s={stale_rad_s}")
        if not (0 <= flip_prob and 0 <= outlier_prob and flip_prob + outlier_prob < 1):
            raise ValueError(f"VisualExchange: flip_prob and outlier_prob must be >= 0 with a sum below 1, got "
                             f"{flip_prob} and {outlier_prob}")
        self.threshold, self.memory_s, self.fresh_s, self.max_step = threshold, memory_s, fresh_s, max_step
        self.stale_rad_s = stale_rad_s
        self.sigma = noise_rad
        self.weights = (1.0 - flip_prob - outlier_prob, flip_prob, outlier_prob / (2 * np.pi))
        self.evidence = np.zeros((n, n))  # symmetric: [a, b] the evidence that a and b hold each other's robots

    def log_likelihood(self, visual: np.ndarray, reported: np.ndarray, sigma: np.ndarray | float | None = None
                       ) -> np.ndarray:
        """Log-likelihood of visual headings ``visual`` (radians) given robot headings ``reported`` (radians) with
        noise ``sigma`` (radians; None: ``noise_rad``); the three broadcast."""
        sigma = self.sigma if sigma is None else np.asarray(sigma)
        d = np.angle(np.exp(1j * (np.asarray(visual) - np.asarray(reported))))
        flipped = np.pi - np.abs(d)
        norm = 1.0 / (np.sqrt(2 * np.pi) * sigma)
        keep, flip, uniform = self.weights
        z, zf = d / sigma, flipped / sigma
        density = norm * (keep * np.exp(-0.5 * z * z) + flip * np.exp(-0.5 * zf * zf))
        return np.asarray(np.log(density + uniform))

    def update(self, held: np.ndarray, visual: np.ndarray, reported: np.ndarray, age: np.ndarray,
               dt: float, scale: np.ndarray | None = None) -> list[tuple[int, int]]:
        """One frame: ``held`` (n) each agent's detection index (-1: none), ``visual`` each detection's visual
        heading (radians), ``reported`` and ``age`` each agent's newest reported heading (radians) and its age
        (seconds; NaN: never heard), ``dt`` seconds since the last frame, ``scale`` (n x n, symmetric) a factor on
        each pair's threshold (None: 1). Returns the pairs found exchanged (the strongest first, each agent at most
        once)."""
        self.evidence *= np.exp(-max(dt, 0.0) / self.memory_s)
        usable = (held >= 0) & np.isfinite(reported) & np.isfinite(age)
        live = np.flatnonzero(usable)
        if len(live) < 2:
            return []
        sigma = np.hypot(self.sigma, self.stale_rad_s * np.maximum(age[live] - self.fresh_s, 0.0))[None, :]
        fit = self.log_likelihood(visual[held[live]][:, None], reported[live][None, :], sigma)  # [i, j]: i's det., j
        own = np.diag(fit)
        gain = np.clip(fit + fit.T - own[:, None] - own[None, :], -self.max_step, self.max_step)
        block = np.maximum(self.evidence[np.ix_(live, live)] + gain, 0.0)
        np.fill_diagonal(block, 0.0)
        self.evidence[np.ix_(live, live)] = block
        return take_pairs(self.evidence, self.threshold if scale is None else self.threshold * scale)
