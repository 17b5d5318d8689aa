"""A simulated world does not depend on its length: F frames are the first F frames of a longer run (same seed)."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from lookalike.sim import NetworkConfig, RobotArrays, RobotWorldConfig, preset, simulate_arrays, simulate_robots

BURSTY = RobotWorldConfig(n_agents=3, network=NetworkConfig(rate_hz=5.0, burst_rate_hz=0.2, burst_s=2.0,
                                                            jitter_s=0.3))


def assert_prefix(short: RobotArrays, long: RobotArrays) -> None:
    """Every per-frame array of ``short`` is byte-equal to the start of ``long``'s; so are the reports received."""
    n = len(short)
    for f in dataclasses.fields(RobotArrays):
        a, b = getattr(short, f.name), getattr(long, f.name)
        if f.name == "reports":
            assert np.array_equal(a.frame_offsets, b.frame_offsets[: n + 1])
            rows = a.frame_offsets[-1]
            for name in ("agent_id", "t_sent", "t_received", "heading"):
                x, y = getattr(a, name), getattr(b, name)[:rows]
                assert x.dtype == y.dtype and x.tobytes() == y.tobytes(), name
            continue
        assert a.dtype == b.dtype and a.tobytes() == b[:n].tobytes(), f.name


@settings(max_examples=30, deadline=None)
@given(name=st.sampled_from(["m3n2", "m5n3", "m10n7"]), noise=st.sampled_from(["ours", "paper"]),
       seed=st.integers(0, 2**32 - 1), short=st.integers(1, 150), extra=st.integers(1, 250))
def test_a_shorter_run_is_the_start_of_a_longer_one(name, noise, seed, short, extra):
    cfg = preset(name, noise)
    assert_prefix(simulate_arrays(cfg, short, seed), simulate_arrays(cfg, short + extra, seed))


@pytest.mark.parametrize("short", [1, 29, 90, 120])
def test_prefix_with_loss_bursts_and_reordered_reports(short):
    long = simulate_arrays(BURSTY, 900, seed=4)
    assert (np.diff(long.reports.t_sent) < 0).any()  # jitter reorders reports
    assert_prefix(simulate_arrays(BURSTY, short, seed=4), long)


def test_rendered_frames_are_a_prefix_too():
    pytest.importorskip("cv2")
    from lookalike.geometry import Camera
    from lookalike.viz.robot_pixels import render_robot_frames

    camera = Camera.default(160, 120)
    cfg = preset("m3n2")
    short = [f.image for f in render_robot_frames(simulate_robots(cfg, 3, 11), camera, 11)]
    long = [f.image for f in render_robot_frames(simulate_robots(cfg, 6, 11), camera, 11)]
    assert all(np.array_equal(a, b) for a, b in zip(short, long[:3]))


def test_simulate_files_of_two_lengths_share_their_first_frames(tmp_path):
    from typer.testing import CliRunner

    from lookalike.cli import app

    lines = {}
    for frames in (20, 45):
        out = tmp_path / str(frames)
        result = CliRunner().invoke(app, ["simulate", "--preset", "m5n3", "--frames", str(frames), "--seed", "2",
                                          "-o", str(out)])
        assert result.exit_code == 0, result.output
        lines[frames] = (out / "m5n3-000002.jsonl").read_text().splitlines()[1:]  # (the header says the length)
    assert len(lines[20]) == 20 and lines[20] == lines[45][:20]
