"""Which two agents hold each other's robots, from the detections' visual headings gathered over seconds (after a
swap of ids the reports barely show, the network's memory of positions keeps the two agents on the wrong robots).

For agents ``a`` and ``b`` that each hold a detection, a frame adds the log-likelihood ratio of "a's detection is b's
robot and b's is a's" over the labels as they are (a visual heading: its robot's reported heading plus Gaussian noise
``noise_rad``, turned by π with probability ``flip_prob``, uniform with ``outlier_prob``), at most ``max_step`` either
way, to a CUSUM decaying with time constant ``memory_s``; a pair passing ``threshold`` is exchanged and starts again.
A report older than ``fresh_s`` counts with its noise widened by ``stale_rad_s`` per second beyond it."""

from __future__ import annotations

import numpy as np

MEMORY_S = 10.0  # time constant of the evidence's decay, seconds
NOISE_RAD = 0.28  # a visual heading's noise around its robot's heading (10 classes, 12 degrees of noise), radians
STALE_RAD_S = 0.5  # widening of an older report's noise, radians per second of age beyond fresh_s
_SQRT_2PI = float(np.sqrt(2 * np.pi))


def take_pairs(evidence: np.ndarray, threshold: float | np.ndarray) -> list[tuple[int, int]]:
    """The pairs ``(a, b)``, ``a < b``, whose symmetric ``evidence`` passes ``threshold`` (scalar or per pair), the
    strongest first, each agent at most once; their rows and columns cleared in place."""
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
        """Parameters as in the module (seconds, radians; ``noise_rad`` a standard deviation)."""
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
        """Log-likelihood of visual headings given robot headings ``reported``, noise ``sigma`` (None: ``noise_rad``);
        radians, broadcast."""
        sigma = self.sigma if sigma is None else np.asarray(sigma)
        turn = np.exp(1j * (np.asarray(visual) - np.asarray(reported)))
        d = np.arctan2(turn.imag, turn.real)  # (np.angle's arithmetic)
        flipped = np.pi - np.abs(d)
        norm = 1.0 / (_SQRT_2PI * sigma)
        keep, flip, uniform = self.weights
        z, zf = d / sigma, flipped / sigma
        density = norm * (keep * np.exp(-0.5 * z * z) + flip * np.exp(-0.5 * zf * zf))
        return np.asarray(np.log(density + uniform))

    def update(self, held: np.ndarray, visual: np.ndarray, reported: np.ndarray, age: np.ndarray,
               dt: float, scale: np.ndarray | None = None) -> list[tuple[int, int]]:
        """One frame: ``held (n,)`` each agent's detection index (-1: none), ``visual`` the detections' visual headings,
        ``reported``/``age`` each agent's newest reported heading and its age (NaN: never heard), ``dt`` seconds since
        the last frame, ``scale (n, n)`` a factor on each pair's threshold (None: 1). Returns :func:`take_pairs`'."""
        self.evidence *= np.exp(-max(dt, 0.0) / self.memory_s)
        usable = (held >= 0) & np.isfinite(reported) & np.isfinite(age)
        live = usable.nonzero()[0]
        k = len(live)
        if k < 2:
            return []
        sigma = np.hypot(self.sigma, self.stale_rad_s * np.maximum(age[live] - self.fresh_s, 0.0))[None, :]
        fit = self.log_likelihood(visual[held[live]][:, None], reported[live][None, :], sigma)  # [i, j]: i's det., j
        own = fit.diagonal()
        gain = fit + fit.T
        gain -= own[:, None]
        gain -= own[None, :]
        np.minimum(np.maximum(gain, -self.max_step, out=gain), self.max_step, out=gain)
        rows, cols = live[:, None], live[None, :]
        block = self.evidence[rows, cols]
        block += gain
        np.maximum(block, 0.0, out=block)
        block.ravel()[:: k + 1] = 0.0
        self.evidence[rows, cols] = block
        return take_pairs(self.evidence, self.threshold if scale is None else self.threshold * scale)
