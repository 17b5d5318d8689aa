"""Tracking-health monitor beside any tracker, from each frame's detections and time: is the detector failing?

Per frame it flags ``dropped`` (frames missing before it), ``empty``, ``too_many`` (over the team size plus
``extra_allowed``), ``score_collapse`` (mean score below ``collapse_ratio`` × the baseline median; none with a
baseline <= 0) and ``too_few`` (informational); over the last ``window`` frames ``unhealthy_frames``, ``undercount``,
``score_collapse`` and ``dropped``."""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass, field

import numpy as np

from lookalike.types import Frame

#: Flag names (``HealthStatus.flags`` / ``window_flags``).
DROPPED, EMPTY, TOO_MANY, TOO_FEW, SCORE_COLLAPSE = "dropped", "empty", "too_many", "too_few", "score_collapse"
UNHEALTHY_FRAMES, UNDERCOUNT = "unhealthy_frames", "undercount"
_INFORMATIONAL = frozenset({TOO_FEW})


@dataclass(frozen=True)
class HealthConfig:
    """Settings of :class:`HealthMonitor` (counts in frames, fractions in [0, 1])."""

    team_size: int | None = None  # known number of targets; None disables the count checks
    window: int = 15
    extra_allowed: int = 0  # detections beyond the team size tolerated in one frame
    min_count_fraction: float = 0.5
    collapse_ratio: float = 0.5
    max_bad_fraction: float = 0.3
    max_dropped: int = 0
    gap_factor: float = 1.5
    baseline_frames: int = 300
    min_baseline: int = 5  # non-empty frames needed before the score checks start

    def __post_init__(self) -> None:
        least = {"team_size": 0, "window": 1, "baseline_frames": 1, "min_baseline": 1, "extra_allowed": 0,
                 "max_dropped": 0}
        for name, low in least.items():
            if getattr(self, name) is not None and getattr(self, name) < low:
                raise ValueError(f"HealthConfig.{name} must be >= {low}, got {getattr(self, name)}")
        for name in ("min_count_fraction", "collapse_ratio", "max_bad_fraction"):
            if not 0 <= getattr(self, name) <= 1:
                raise ValueError(f"HealthConfig.{name} must be in [0, 1], got {getattr(self, name)}")
        if not self.gap_factor > 1:
            raise ValueError(f"HealthConfig.gap_factor must be > 1, got {self.gap_factor}")


@dataclass(frozen=True)
class HealthStatus:
    """The detector's health at one frame: its own flags and those of the window ending there (``reasons``,
    ``window_reasons`` in words; ``mean_score`` NaN without detections; ``dropped`` frames missing before it)."""

    frame_index: int
    n_detections: int
    mean_score: float
    dropped: int
    flags: frozenset[str] = field(default_factory=frozenset)
    reasons: tuple[str, ...] = ()
    window_flags: frozenset[str] = field(default_factory=frozenset)
    window_reasons: tuple[str, ...] = ()

    @property
    def frame_healthy(self) -> bool:
        """No flag of this frame other than informational ones (``too_few``)."""
        return not (self.flags - _INFORMATIONAL)

    @property
    def window_healthy(self) -> bool:
        """No flag on the window ending at this frame."""
        return not self.window_flags

    @property
    def healthy(self) -> bool:
        """Frame and window healthy: identities may be relied on."""
        return self.frame_healthy and self.window_healthy


class HealthMonitor:
    """Online detector-health flags, one :class:`HealthStatus` per :meth:`update` (frames in order)."""

    def __init__(self, config: HealthConfig | None = None) -> None:
        self.config = config or HealthConfig()
        self.reset()

    def reset(self) -> None:
        """Forget the history (window, baseline, timing)."""
        cfg = self.config
        self._last_index: int | None = None
        self._last_time: float | None = None
        self._intervals: deque[float] = deque(maxlen=50)
        self._window: deque[tuple[int, float, int, bool]] = deque(maxlen=cfg.window)  # count, score, dropped, ok
        self._baseline_scores: deque[float] = deque(maxlen=cfg.baseline_frames)

    @property
    def baseline_score(self) -> float:
        """Median per-frame mean score of earlier non-collapsed frames (NaN until ``min_baseline`` frames)."""
        if len(self._baseline_scores) < self.config.min_baseline:
            return float("nan")
        return float(np.median(np.fromiter(self._baseline_scores, float)))

    def update(self, frame: Frame) -> HealthStatus:
        """Assess ``frame`` (its detections' count and scores, its index and time)."""
        cfg = self.config
        det = frame.detections
        n = len(det)
        mean_score = float(np.mean(det.score)) if n else float("nan")
        dropped = self._dropped(frame)
        found: dict[str, str] = {}  # flag -> reason, in order
        if dropped:
            found[DROPPED] = f"{dropped} frame(s) dropped before this one"
        if n == 0 and cfg.team_size != 0:
            found[EMPTY] = "no detections"
        if cfg.team_size is not None:
            if n > cfg.team_size + cfg.extra_allowed:
                found[TOO_MANY] = f"{n} detections for a team of {cfg.team_size}"
            elif 0 < n < cfg.team_size:
                found[TOO_FEW] = f"{n} of a team of {cfg.team_size} detected"
        baseline = self.baseline_score
        checks_scores = np.isfinite(baseline) and baseline > 0
        if n and checks_scores and mean_score < cfg.collapse_ratio * baseline:
            found[SCORE_COLLAPSE] = f"mean score {mean_score:.2f} < {cfg.collapse_ratio:.0%} of usual {baseline:.2f}"
        if n and SCORE_COLLAPSE not in found:
            self._baseline_scores.append(mean_score)
        ok = not (found.keys() - _INFORMATIONAL)
        self._window.append((n, mean_score, dropped, ok))
        window = self._window_flags(baseline if checks_scores else float("nan"))
        return HealthStatus(frame.index, n, mean_score, dropped, frozenset(found), tuple(found.values()),
                            frozenset(window), tuple(window.values()))

    def _dropped(self, frame: Frame) -> int:
        """Frames missing between the previous frame and this one (from indices, else from times)."""
        index, t = int(frame.index), float(frame.time)
        last_index, last_time = self._last_index, self._last_time
        self._last_index, self._last_time = index, t
        if last_index is None or last_time is None:
            return 0
        if index <= last_index:
            raise ValueError(f"frame.index: frames must come in order, got {index} after {last_index}")
        missing = index - last_index - 1
        step = t - last_time
        usual = float(np.median(np.fromiter(self._intervals, float))) if self._intervals else None
        if missing == 0 and step > 0:
            if usual is not None and usual > 0 and step > self.config.gap_factor * usual:
                missing = max(round(step / usual) - 1, 1)
            else:
                self._intervals.append(step)
        elif missing > 0 and step > 0:
            self._intervals.append(step / (missing + 1))
        return missing

    def _window_flags(self, baseline: float) -> dict[str, str]:
        cfg = self.config
        counts = np.array([w[0] for w in self._window], dtype=float)
        scores = np.array([w[1] for w in self._window], dtype=float)
        dropped = sum(w[2] for w in self._window)
        bad = sum(not w[3] for w in self._window)
        found: dict[str, str] = {}  # flag -> reason, in order
        m = len(self._window)
        if bad > cfg.max_bad_fraction * m:
            found[UNHEALTHY_FRAMES] = f"{bad}/{m} recent frames unhealthy"
        if cfg.team_size and counts.mean() < cfg.min_count_fraction * cfg.team_size:
            found[UNDERCOUNT] = f"{counts.mean():.1f} detections/frame for a team of {cfg.team_size}"
        if np.isfinite(baseline) and np.isfinite(scores).any():
            mean = float(np.nanmean(scores))
            if mean < cfg.collapse_ratio * baseline:
                found[SCORE_COLLAPSE] = (f"recent mean score {mean:.2f} < {cfg.collapse_ratio:.0%} of usual "
                                         f"{baseline:.2f}")
        if dropped > cfg.max_dropped:
            found[DROPPED] = f"{dropped} frame(s) dropped in the last {m}"
        return found


HEALTH_CSV_HEADER = ("frame", "n_detections", "mean_score", "dropped", "frame_healthy", "window_healthy",
                     "flags", "window_flags", "reasons")


def health_row(status: HealthStatus) -> list[str]:
    """One CSV row (see :data:`HEALTH_CSV_HEADER`; frame 1-based, flags joined by ``|``)."""
    score = "" if not np.isfinite(status.mean_score) else f"{status.mean_score:.4f}"
    return [str(status.frame_index + 1), str(status.n_detections), score, str(status.dropped),
            str(int(status.frame_healthy)), str(int(status.window_healthy)),
            "|".join(sorted(status.flags)), "|".join(sorted(status.window_flags)),
            "; ".join(status.reasons + status.window_reasons)]
