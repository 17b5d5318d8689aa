import numpy as np
import pytest

from lookalike.trackers import HealthConfig, HealthMonitor, HealthStatus
from lookalike.trackers.parts.health import (
    DROPPED,
    EMPTY,
    SCORE_COLLAPSE,
    TOO_FEW,
    TOO_MANY,
    UNDERCOUNT,
    UNHEALTHY_FRAMES,
    health_row,
)
from lookalike.types import Detections, Frame


def assess(frames: list[Frame], config: HealthConfig | None = None) -> list[HealthStatus]:
    """:class:`HealthStatus` of each of ``frames`` (in order) from a fresh :class:`HealthMonitor`."""
    monitor = HealthMonitor(config)
    return [monitor.update(f) for f in frames]


def _frame(index: int, n: int, score: float = 0.9, fps: float = 10.0, time: float | None = None) -> Frame:
    xywh = np.column_stack([np.arange(n) * 50.0, np.full(n, 10.0), np.full(n, 20.0), np.full(n, 40.0)])
    det = Detections(xywh=xywh.reshape(-1, 4), score=np.full(n, score))
    return Frame(index=index, time=index / fps if time is None else time, detections=det)


def test_team_of_four_steady_is_healthy():
    statuses = assess([_frame(k, 4) for k in range(40)], HealthConfig(team_size=4))
    assert all(isinstance(s, HealthStatus) and s.healthy for s in statuses)
    assert all(not s.flags and not s.reasons for s in statuses)


def test_empty_frames_flag_frame_then_window():
    cfg = HealthConfig(team_size=4, window=10)
    frames = [_frame(k, 4) for k in range(20)] + [_frame(k, 0) for k in range(20, 30)]
    statuses = assess(frames, cfg)
    first_empty = statuses[20]
    assert EMPTY in first_empty.flags and not first_empty.frame_healthy
    assert "no detections" in first_empty.reasons
    assert first_empty.window_healthy  # one bad frame in ten is tolerated
    last = statuses[-1]
    assert {UNHEALTHY_FRAMES, UNDERCOUNT} <= last.window_flags and not last.healthy
    assert any("team of 4" in r for r in last.window_reasons)


def test_counts_inconsistent_with_team():
    cfg = HealthConfig(team_size=4, window=5)
    s = assess([_frame(0, 4), _frame(1, 6), _frame(2, 2)], cfg)
    assert TOO_MANY in s[1].flags and not s[1].frame_healthy and "6 detections for a team of 4" in s[1].reasons
    assert TOO_FEW in s[2].flags and s[2].frame_healthy  # divers leave the view: informational only
    loose = assess([_frame(0, 4), _frame(1, 5)], HealthConfig(team_size=4, extra_allowed=1))
    assert loose[1].healthy
    # no team size: the count checks are off, an empty frame is still flagged
    free = assess([_frame(0, 9), _frame(1, 0)], HealthConfig())
    assert free[0].healthy and EMPTY in free[1].flags


def test_score_collapse_and_baseline_not_poisoned():
    cfg = HealthConfig(team_size=4, window=8)
    frames = [_frame(k, 4, 0.9) for k in range(30)] + [_frame(k, 4, 0.2) for k in range(30, 60)]
    statuses = assess(frames, cfg)
    assert all(s.healthy for s in statuses[:30])
    assert SCORE_COLLAPSE in statuses[30].flags
    assert all(SCORE_COLLAPSE in s.flags for s in statuses[30:])  # collapsed frames never become the baseline
    assert SCORE_COLLAPSE in statuses[-1].window_flags and not statuses[-1].healthy
    # a mild dip is not a collapse
    dip = assess([_frame(k, 4, 0.9) for k in range(20)] + [_frame(20, 4, 0.6)], cfg)
    assert dip[-1].healthy


def test_no_score_check_before_baseline():
    s = assess([_frame(0, 4, 0.9), _frame(1, 4, 0.01)], HealthConfig(team_size=4))
    assert s[1].healthy


def test_dropped_frames_from_index_and_time():
    cfg = HealthConfig(team_size=2, window=10)
    by_index = assess([_frame(0, 2), _frame(1, 2), _frame(5, 2)], cfg)
    assert by_index[2].dropped == 3 and DROPPED in by_index[2].flags and DROPPED in by_index[2].window_flags
    # contiguous indices but a 0.4 s gap in 10 frames/s timestamps: 3 frames lost
    times = [0.0, 0.1, 0.2, 0.3, 0.7, 0.8]
    by_time = assess([_frame(k, 2, time=t) for k, t in enumerate(times)], cfg)
    assert [s.dropped for s in by_time] == [0, 0, 0, 0, 3, 0]
    assert DROPPED in by_time[-1].window_flags  # still within the window
    with pytest.raises(ValueError, match="frame.index"):
        assess([_frame(3, 2), _frame(3, 2)], cfg)


def test_reset_and_config_validation():
    m = HealthMonitor(HealthConfig(team_size=4))
    for k in range(10):
        m.update(_frame(k, 4))
    assert np.isclose(m.baseline_score, 0.9)
    m.reset()
    assert np.isnan(m.baseline_score)
    assert m.update(_frame(0, 4)).healthy  # index restarts without an order error
    for bad in ({"team_size": -1}, {"window": 0}, {"collapse_ratio": 1.5}, {"gap_factor": 1.0}):
        with pytest.raises(ValueError, match="HealthConfig"):
            HealthConfig(**bad)


def test_health_row():
    s = assess([_frame(0, 4), _frame(1, 0)], HealthConfig(team_size=4))
    row = health_row(s[1])
    assert row[0] == "2" and row[1] == "0" and row[2] == "" and row[4] == "0" and "empty" in row[6]
