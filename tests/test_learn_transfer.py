"""Warm start across set-ups (learn.transfer): columns and rows mapped robot by robot, slot by slot."""

from __future__ import annotations

import numpy as np
import pytest

from lookalike.learn.transfer import transfer_weights
from lookalike.trackers.lstm.checkpoint import CheckpointError, NetworkWeights
from lookalike.trackers.lstm.encoding import EncodingSpec
from lookalike.trackers.lstm.network import NumpyAssociationNet


def _weights(spec: EncodingSpec, hidden: int = 4, layers: int = 2, seed: int = 0) -> NetworkWeights:
    rng = np.random.default_rng(seed)
    lay = []
    for i in range(layers):
        width = spec.n_inputs if i == 0 else hidden
        lay.append({"w_ih": rng.normal(size=(4 * hidden, width)), "w_hh": rng.normal(size=(4 * hidden, hidden)),
                    "b_ih": rng.normal(size=4 * hidden), "b_hh": rng.normal(size=4 * hidden)})
    out = spec.n_slots * spec.n_classes
    return NetworkWeights(spec, "lstm", hidden, lay, rng.normal(size=(out, hidden)), rng.normal(size=out),
                          rng.normal(size=spec.n_inputs), rng.uniform(0.5, 2.0, size=spec.n_inputs))


def test_paper_m5n3_to_m10n7_maps_blocks() -> None:
    src_spec, dst_spec = EncodingSpec(3, 5, protocol="paper"), EncodingSpec(7, 10, protocol="paper")
    src = _weights(src_spec)
    mean, std = np.zeros(dst_spec.n_inputs), np.ones(dst_spec.n_inputs)
    dst = transfer_weights(src, dst_spec, mean, std, np.random.default_rng(1), jitter=0.0)
    w0, s0 = dst.layers[0]["w_ih"], src.layers[0]["w_ih"]
    assert w0.shape == (16, dst_spec.n_inputs)
    for j in range(7):  # one input per agent in the paper layout
        np.testing.assert_array_equal(w0[:, j], s0[:, j % 3])
    for k in range(10):
        np.testing.assert_array_equal(w0[:, 7 + 4 * k: 11 + 4 * k], s0[:, 3 + 4 * (k % 5): 7 + 4 * (k % 5)])
    head, shead = dst.head_weight.reshape(10, 8, 4), src.head_weight.reshape(5, 4, 4)
    for k in range(10):
        np.testing.assert_array_equal(head[k, 7], shead[k % 5, 3])  # false positive <- false positive
        for c in range(7):
            np.testing.assert_array_equal(head[k, c], shead[k % 5, c % 3])
    np.testing.assert_array_equal(dst.layers[1]["w_hh"], src.layers[1]["w_hh"])
    assert dst.input_mean.shape == (dst_spec.n_inputs,)
    NumpyAssociationNet(dst)  # a loadable network


def test_originals_keep_their_weights_and_repeats_get_noise() -> None:
    src_spec, dst_spec = EncodingSpec(2, 3, protocol="paper"), EncodingSpec(3, 5, protocol="paper")
    src = _weights(src_spec)
    dst = transfer_weights(src, dst_spec, np.zeros(dst_spec.n_inputs), np.ones(dst_spec.n_inputs),
                           np.random.default_rng(0), jitter=0.1)
    w0, s0 = dst.layers[0]["w_ih"], src.layers[0]["w_ih"]
    np.testing.assert_array_equal(w0[:, :2], s0[:, :2])
    assert not np.array_equal(w0[:, 2], s0[:, 0])  # agent 2 repeats agent 0, with noise
    np.testing.assert_allclose(w0[:, 2], s0[:, 0], atol=1.0)


def test_refuses_another_protocol() -> None:
    src = _weights(EncodingSpec(2, 3, protocol="paper"))
    dst_spec = EncodingSpec(3, 5)
    with pytest.raises(CheckpointError, match="protocol"):
        transfer_weights(src, dst_spec, np.zeros(dst_spec.n_inputs), np.ones(dst_spec.n_inputs),
                         np.random.default_rng(0))


def test_train_init_transfer_command(tmp_path) -> None:
    pytest.importorskip("torch", reason="training needs torch (the 'train' extra)")
    import json

    from typer.testing import CliRunner

    from lookalike.cli import app
    from lookalike.trackers.lstm.weights import WEIGHTS_DIR

    source = WEIGHTS_DIR / "lstm_paper_m3_n2.npz"
    if not source.is_file():
        pytest.skip("shipped paper-protocol M=3, N=2 weights absent")
    args = ["train", "--preset", "m5n3", "--protocol", "paper", "-o", str(tmp_path / "run"), "--steps", "1",
            "--sequence-length", "150", "--batch-size", "2"]
    refused = CliRunner().invoke(app, [*args, "--init-from", str(source)])
    assert refused.exit_code == 2 and "n_agents" in refused.output
    r = CliRunner().invoke(app, [*args, "--init-from", str(source), "--init-transfer"])
    assert r.exit_code == 0, r.output
    meta = json.loads((tmp_path / "run" / "model.json").read_text())
    assert (meta["n_agents"], meta["n_slots"], meta["protocol"]) == (3, 5, "paper")
    assert meta["info"]["transferred_from"]["n_agents"] == 2
    bad = CliRunner().invoke(app, [*args, "--init-transfer"])
    assert bad.exit_code == 2 and "--init-transfer needs --init-from" in bad.output
