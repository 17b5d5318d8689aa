"""The point path: boxtrack gets the points' velocity noise (POINT_VEL_NOISE), a lone point gets a box of its step."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pytest

from lookalike.io.points import POINT_VEL_NOISE
from lookalike.pipeline import TrackRequest, run
from lookalike.pipeline.closed import point_tracker
from lookalike.trackers import boxtrack_config as const
from lookalike.trackers.boxtrack import BoxTrack
from lookalike.trackers.registry import make_tracker


def test_boxtrack_default_motion_model_and_hook() -> None:
    assert BoxTrack()._space.vel_noise == const.VEL_NOISE
    assert BoxTrack(vel_noise=0.05)._space.vel_noise == 0.05
    with pytest.raises(ValueError, match="vel_noise"):
        BoxTrack(vel_noise=0.0)


def test_point_tracker_keeps_config_and_uses_point_noise() -> None:
    trk = make_tracker("boxtrack", n_init=2, max_targets=3)
    pt = point_tracker(trk)
    assert pt.config == trk.config and pt._space.vel_noise == POINT_VEL_NOISE
    sort = make_tracker("sort")
    assert point_tracker(sort) is sort


def _points_csv(path: Path) -> Path:
    rows = [f"{k},{10 + 3 * k + 40 * i},{50 + 30 * i}" for k in range(1, 31) for i in range(3)]
    path.write_text("frame,x,y\n" + "\n".join(rows) + "\n")
    return path


@pytest.mark.parametrize("offline", [False, True])
def test_point_path_builds_boxtrack_with_point_noise(tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
                                                     offline: bool) -> None:
    seen: list[float | None] = []
    init = BoxTrack.__init__

    def spy(self: BoxTrack, config: Any = None, *, vel_noise: float | None = None) -> None:
        seen.append(vel_noise)
        init(self, config, vel_noise=vel_noise)

    monkeypatch.setattr(BoxTrack, "__init__", spy)
    out = tmp_path / "tracks.txt"
    run(TrackRequest(out, "boxtrack", points=_points_csv(tmp_path / "p.csv"), targets=3, offline=offline))
    assert POINT_VEL_NOISE in seen
    rows = np.loadtxt(out, delimiter=",", ndmin=2)
    assert len(np.unique(rows[:, 1])) == 3


def test_single_target_boxes_follow_the_step() -> None:
    from lookalike.io.points import PointFrames, points_to_rows, typical_step

    pts = PointFrames([np.array([[10.0 * k, 0.0]]) for k in range(20)])  # one point, 10 units a frame
    assert typical_step(pts) == 10.0
    rows = points_to_rows(pts)
    np.testing.assert_allclose(rows[:, 4:6], 20.0)  # no spacing: twice the step, consecutive boxes overlap
    assert points_to_rows(PointFrames([np.array([[1.0, 2.0]])]))[0, 4] == 1.0  # neither: 1
