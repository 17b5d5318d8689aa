"""Seed A, faithfully (issue 21): the paper's noise model, its input protocol, localisers, Table III."""

from __future__ import annotations

import json

import numpy as np
import pytest
from typer.testing import CliRunner

from lookalike.bench.ident_paper import margin_rows, resolve_identifier
from lookalike.bench.table3 import draw_windows, table3_rows
from lookalike.cli import app
from lookalike.learn.paper_protocol import NoiseMixSampler, arrays_to_training_paper, noise_worlds
from lookalike.sim import NOISE_MODELS, noise_sensor, preset, simulate_arrays, simulate_robots
from lookalike.sim.robots_sensors import position_noise_std
from lookalike.trackers import make_tracker
from lookalike.trackers.lstm.encoding import EncodingSpec, encode_frame
from lookalike.trackers.parts.agents import BeaconMemory, decode
from lookalike.trackers.parts.identity.localiser import KalmanLocaliser, LowPassLocaliser, make_localiser

runner = CliRunner()


def _errors(noise: str) -> np.ndarray:
    a = simulate_arrays(preset("m3n2", noise), 1500, 7)
    used = a.det_valid & (a.det_label >= 0)
    frame = np.nonzero(used)[0]
    return a.det_position[used] - a.true_position[frame, a.det_label[used]]


def test_paper_noise_is_larger_across_the_image_than_in_depth():
    d = np.array([1.0, 3.0, 6.0])
    paper = position_noise_std(d, noise_sensor("paper"))
    ours = position_noise_std(d, noise_sensor("ours"))
    assert (paper[:, 1] > paper[:, 0]).all()  # observer y (image columns) noisier than x (depth, rows)
    assert (ours[:, 0] > ours[:, 1]).all()
    across, depth = _errors("paper").std(axis=0)[::-1]
    assert across > 1.5 * depth  # and the simulated detections follow it
    assert set(NOISE_MODELS) == {"paper", "ours"}
    assert preset("m5n3", "paper").sensor.fp_per_frame == preset("m5n3").sensor.fp_per_frame
    with pytest.raises(ValueError, match="noise"):
        preset("m3n2", "both")


def test_paper_encoding_has_n_plus_4m_inputs_and_matches_the_training_arrays():
    spec = EncodingSpec(2, 3, protocol="paper")
    assert spec.n_inputs == 2 + 4 * 3
    seq = simulate_robots(preset("m3n2", "paper"), 120, 3)
    x, y = arrays_to_training_paper(spec, seq.arrays)
    memory, rows = BeaconMemory(2), []
    for frame in seq.frames():
        memory.add(frame)
        rows.append(encode_frame(spec, frame.detections, memory.heading, memory.age(frame.time))[0])
    assert x.shape == (120, 14) and np.allclose(np.array(rows), x)
    assert np.abs(x[:, :2]).max() <= 1.0  # headings / pi
    assert x.shape == NoiseMixSampler(noise_worlds("m3n2", "mix"), spec)(5, 120, None)[0].shape
    with pytest.raises(ValueError):
        EncodingSpec(2, 3, relative_headings=True, protocol="paper")


def test_per_slot_decoding_is_the_argmax():
    prob = np.array([[0.6, 0.3, 0.1], [0.7, 0.2, 0.1], [0.1, 0.1, 0.8]])
    label, conf = decode(prob, np.arange(3), 3, one_to_one=False)
    assert label.tolist() == [0, 0, -1] and np.allclose(conf, [0.6, 0.7, 0.8])


def test_kalman_localiser_reduces_the_error_of_a_noisy_track():
    rng = np.random.default_rng(0)
    t = np.arange(300) / 30.0
    truth = np.column_stack([3.0 + 0.3 * np.sin(0.5 * t), -0.5 + 0.2 * t])
    noisy = truth + rng.normal(0.0, 0.15, truth.shape)
    one = np.ones(1)
    kal, low = KalmanLocaliser(1), LowPassLocaliser(1)
    k_est = np.array([kal.update(ti, z[None], one)[0] for ti, z in zip(t, noisy)])
    l_est = np.array([low.update(ti, z[None], one)[0] for ti, z in zip(t, noisy)])
    raw = np.linalg.norm(noisy - truth, axis=1).mean()
    assert np.linalg.norm(k_est - truth, axis=1).mean() < 0.7 * raw
    assert np.allclose(l_est, noisy)  # Eq. 3 with alpha = 1 follows the detections


def test_localisers_handle_missing_agents_and_refuse_unknown_names():
    loc = make_localiser("kalman", 2)
    out = loc.update(0.0, np.array([[2.0, 0.0], [np.nan, np.nan]]), np.array([0.9, 0.0]))
    assert np.isfinite(out[0]).all() and np.isnan(out[1]).all()
    out = loc.update(10.0, np.full((2, 2), np.nan), np.zeros(2))  # lost longer than max_coast_s
    assert np.isnan(out).all()
    low = make_localiser("lowpass", 1)
    low.update(0.0, np.array([[1.0, 1.0]]), np.array([1.0]))
    assert np.allclose(low.update(0.1, np.array([[3.0, 1.0]]), np.array([0.25])), [[1.5, 1.0]])
    with pytest.raises(ValueError, match="localiser"):
        make_localiser("median", 1)


@pytest.mark.parametrize("params", [{"localiser": "lowpass"}, {"localiser": "kalman"},
                                    {"protocol": "paper", "one_to_one": False}])
def test_lstm_options_run(params):
    seq = simulate_robots(preset("m3n2"), 60, 11)
    tracker = make_tracker("lstm", n_agents=2, n_slots=3, **params)
    for frame in seq.frames():
        for snap in tracker.update(frame):
            assert snap.position is not None and np.isfinite(snap.position).all()
    with pytest.raises(ValueError):
        make_tracker("lstm", n_agents=2, n_slots=3, localiser="median")


def test_variants_and_margins():
    assert resolve_identifier("lstm-paper") == ("lstm", {"protocol": "paper", "one_to_one": False})
    assert resolve_identifier("jpda") == ("jpda", {})
    rows = [{"Setup": "M=3, N=2", "Tracker": "kalman_ha", "Success rate (%)": 80.0},
            {"Setup": "M=3, N=2", "Tracker": "lstm-paper", "Success rate (%)": 95.0}]
    (m,) = margin_rows(rows, ["m3n2"], ["M=3, N=2"])
    assert m["Margin (points)"] == 15.0 and m["Paper's margin (points)"] == 20.6


def test_table3_windows_and_rows():
    windows = draw_windows([50, 100], [120, 80], 3, seed=1)
    assert len(windows) == 6 and all(i == 0 for n, i, _ in windows if n == 100)
    assert all(first + n <= (120, 80)[i] for n, i, first in windows)
    with pytest.raises(ValueError, match="no recording"):
        draw_windows([500], [120], 1, seed=0)
    seqs = [simulate_robots(preset("m3n2"), 120, s) for s in (1, 2)]
    (row,) = table3_rows(seqs, ["kalman_ha"], [50], 2, seed=0)
    assert set(row) == {"Tracker", "50 frames (%)", "Total, 240 frames (%)", "Localisation error (m)"}


def test_cli_options_parse(tmp_path):
    pytest.importorskip("torch")
    r = runner.invoke(app, ["simulate", "--preset", "m3n2", "--frames", "5", "--noise", "paper", "-o", str(tmp_path)])
    assert r.exit_code == 0, r.output
    header = json.loads(next(tmp_path.glob("*.jsonl")).read_text().splitlines()[0])
    assert header["config"]["sensor"]["std_y_per_m"] > header["config"]["sensor"]["std_x_per_m"]
    for args in (["simulate", "--noise", "x", "-o", str(tmp_path)], ["bench", "ident", "--noise", "x"],
                 ["bench", "ident", "--lengths", "a,b"], ["bench", "ident", "--recordings", str(tmp_path / "none")],
                 ["train", "--protocol", "x", "-o", str(tmp_path / "run")],
                 ["train", "--noise", "x", "-o", str(tmp_path / "run")]):
        bad = runner.invoke(app, args)
        assert bad.exit_code == 2 and "\n" not in bad.output.strip(), (args, bad.output)
    ok = runner.invoke(app, ["bench", "ident", "--setups", "m3n2", "--trackers", "kalman_ha,lstm-paper",
                             "--sequences", "1", "--frames", "60", "--noise", "paper"])
    assert ok.exit_code == 0 and "Paper's" in ok.output, ok.output
