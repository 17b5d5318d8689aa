"""Frame clock: converts frame time stamps into motion-model steps."""

from __future__ import annotations

import math
from collections import deque

RESET_HINT = "; a new sequence needs the tracker's reset() first"
"""Ends the message of a time going backwards: the usual cause is one tracker object fed a second sequence."""
RECENT_STEPS = 64  # the latest positive steps whose median says how long a frame's step is


class FrameClock:
    """Turns time stamps (seconds) into a number of nominal frame intervals.

    Per-frame models (SORT's noise is defined per frame) use ``steps(t)``: 1.0 for a regular frame, 2.0 after a skipped
    frame. The nominal interval is given, or the smallest positive step seen so far (1.0 s until a second frame
    arrives), leaving out steps shorter than half the median of the latest :data:`RECENT_STEPS`: two frames delivered
    almost together (a live camera's jitter, a repeated stamp) count as a fraction of a step, and do not make every
    later frame count as many."""

    def __init__(self, interval_s: float | None = None) -> None:
        self._fixed = interval_s
        self.interval = interval_s or 1.0
        self._last: float | None = None
        self._seen_step = False
        self._recent: deque[float] = deque(maxlen=RECENT_STEPS)

    def steps(self, time_s: float) -> float:
        """Nominal intervals elapsed since the previous call (1.0 on the first call); a refused time changes nothing."""
        last, now = self._last, float(time_s)
        if last is None:
            self._last = now
            return 1.0
        dt = now - last
        if not math.isfinite(dt) or dt < 0:
            raise ValueError(f"frame time went backwards: {last} s then {time_s} s{RESET_HINT}")
        self._last = now
        if dt == 0:
            return 0.0
        if self._fixed is None:
            self._recent.append(dt)
            ordered = sorted(self._recent)
            half = ordered[len(ordered) // 2] / 2
            if dt >= half and (not self._seen_step or dt < self.interval):
                self.interval = dt
            elif self.interval < half:  # the interval so far was two frames delivered together, not a frame's step
                self.interval = next(s for s in ordered if s >= half)
        self._seen_step = True
        return dt / self.interval
