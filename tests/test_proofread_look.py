"""Proofreading a blob video's closed set re-solves it from the video's cached blobs with the learned look."""

from __future__ import annotations

import numpy as np
import pytest
from typer.testing import CliRunner

from lookalike.cli import app
from lookalike.io.arena_files import write_arena
from lookalike.io.motchallenge import read_mot, write_mot
from lookalike.sim.arena import ArenaConfig

pytest.importorskip("cv2")


def test_tracks_of_the_blob_command_re_solve_with_the_look_and_edited_ones_do_not(tmp_path, monkeypatch):
    from lookalike.pipeline.proofread_input import blob_solver_input

    monkeypatch.setenv("LOOKALIKE_CACHE", str(tmp_path / "cache"))
    cfg = ArenaConfig(n_animals=3, frames=60, image_px=300, body_length_px=40.0, body_width_px=7.0)
    video = write_arena(tmp_path / "arena", cfg, seed=2).video
    tracks = tmp_path / "t.txt"
    runner = CliRunner()
    r = runner.invoke(app, ["track", "--video", str(video), "--detector", "blob", "-t", "boxtrack", "--targets", "3",
                            "-o", str(tracks)])
    assert r.exit_code == 0, r.output
    found = blob_solver_input(video, tracks, 3, cfg.frame_rate_hz)
    assert found is not None
    solver, shapes, parts = found
    assert solver.shape[1] == 10 and solver[:, 9].max() < len(shapes) == len(parts)
    t = read_mot(tracks)
    edited = np.column_stack([t.frame, t.track_id, t.xywh, t.conf, np.full((len(t), 3), -1.0)])
    late = edited[:, 0] > 30
    edited[late, 1] = edited[late, 1] % 3 + 1  # ids rotated in the second half: not what the solver gives
    write_mot(tmp_path / "edited.txt", edited)
    assert blob_solver_input(video, tmp_path / "edited.txt", 3, cfg.frame_rate_hz) is None
    r = runner.invoke(app, ["proofread", "--video", str(video), "--tracks", str(tracks), "--targets", "3",
                            "--export"])
    assert r.exit_code == 0 and "with each animal's look" in r.output, r.output


def test_the_blob_closed_set_writes_a_confidence_that_weighs_each_rows_look(tmp_path, monkeypatch):
    from lookalike.pipeline import TrackRequest, run
    from lookalike.trackers.offline.confidence import assignment_confidence, by_frame_and_id

    monkeypatch.setenv("LOOKALIKE_CACHE", str(tmp_path / "cache"))
    cfg = ArenaConfig(n_animals=3, frames=60, image_px=300, body_length_px=40.0, body_width_px=7.0)
    video = write_arena(tmp_path / "arena", cfg, seed=2).video
    out = tmp_path / "t.txt"
    result = run(TrackRequest(out, "boxtrack", video=str(video), detector="blob", targets=3))
    look = result.looks[out]
    t = read_mot(out)
    rows = np.column_stack([t.frame, t.track_id, t.xywh, t.conf, np.full((len(t), 3), -1.0)])
    margin = by_frame_and_id(rows, look)
    assert look.shape[1] == 3 and np.any(margin > 0)
    np.testing.assert_allclose(t.conf, np.round(assignment_confidence(rows, cfg.frame_rate_hz, look=margin), 3))
    plain = np.round(assignment_confidence(rows, cfg.frame_rate_hz), 3)
    assert np.all(t.conf[margin > 0] >= plain[margin > 0]) and np.all(t.conf[margin < 0] <= plain[margin < 0])
    assert not np.array_equal(t.conf, plain)
