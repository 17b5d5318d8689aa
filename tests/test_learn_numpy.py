import json
import subprocess
import sys

import numpy as np
import pytest

from lookalike.trackers.lstm import CheckpointError, EncodingSpec, NumpyAssociationNet, load_weights, save_weights
from lookalike.trackers.lstm.encoding import encode_frame
from lookalike.types import Detections

torch = pytest.importorskip("torch", reason="torch (the 'train' extra) is needed to compare against")


@pytest.mark.parametrize("cell", ["lstm", "gru"])
def test_numpy_equals_torch(cell, tmp_path):
    from lookalike.learn.model import AssociationNet

    torch.manual_seed(0)
    spec = EncodingSpec(n_agents=3, n_slots=5)
    net = AssociationNet(spec, hidden=16, num_layers=3, cell=cell)
    rng = np.random.default_rng(0)
    x = rng.normal(size=(2, 40, spec.n_inputs))
    net.set_normalisation(x.reshape(-1, spec.n_inputs).mean(0), x.reshape(-1, spec.n_inputs).std(0))
    with torch.no_grad():
        logp, _ = net(torch.as_tensor(x))
    path = save_weights(net.export({"note": "test"}), tmp_path / "m")
    numpy_net = NumpyAssociationNet(load_weights(path, n_agents=3, n_slots=5))
    numpy_net.reset(batch=2)
    for t in range(x.shape[1]):
        p = numpy_net.step(x[:, t])
        np.testing.assert_allclose(p, np.exp(logp[:, t].numpy()), atol=1e-5)


def _saved(tmp_path):
    from lookalike.learn.model import AssociationNet

    net = AssociationNet(EncodingSpec(2, 3), hidden=8, num_layers=2)
    return save_weights(net.export(), tmp_path / "m")


def test_saving_weights_leaves_the_two_files_and_no_temporary(tmp_path):
    path = _saved(tmp_path)
    _saved(tmp_path)  # over the old files
    assert sorted(p.name for p in tmp_path.iterdir()) == ["m.json", "m.npz"]
    assert load_weights(path, n_agents=2).spec.n_slots == 3


def test_mismatched_checkpoints_are_refused(tmp_path):
    path = _saved(tmp_path)
    with pytest.raises(CheckpointError, match="trained for n_agents=2, but 7 was requested"):
        load_weights(path, n_agents=7)
    with pytest.raises(CheckpointError, match="n_slots=3, but 10"):
        load_weights(path, n_slots=10)
    meta = json.loads(path.with_suffix(".json").read_text())
    meta["format_version"] = 99
    path.with_suffix(".json").write_text(json.dumps(meta))
    with pytest.raises(CheckpointError, match="format_version 99 is not supported"):
        load_weights(path)


def test_wrong_shaped_weights_are_refused(tmp_path):
    path = _saved(tmp_path)
    data = dict(np.load(path))
    data["layer1.w_hh"] = np.zeros((32, 7))
    np.savez(path, **data)
    with pytest.raises(CheckpointError, match=r"layer1.w_hh has shape \(32, 7\), expected \(32, 8\)"):
        load_weights(path)
    path.write_bytes(b"not a zip file")
    with pytest.raises(CheckpointError, match="cannot read the weights"):
        load_weights(path)


def test_non_finite_or_missing_layer_weights_are_refused(tmp_path):
    path = _saved(tmp_path)
    data = dict(np.load(path))
    data["layer1.w_hh"] = np.full(data["layer1.w_hh"].shape, np.nan)
    np.savez(path, **data)
    with pytest.raises(CheckpointError, match=r"m.npz: weights: layer1.w_hh holds NaN or infinity"):
        load_weights(path)
    del data["layer1.w_hh"]
    np.savez(path, **data)
    with pytest.raises(CheckpointError, match=r"layer1.w_hh is missing"):
        load_weights(path)


def test_encoding_layout():
    spec = EncodingSpec(n_agents=2, n_slots=2)
    det = Detections(position=[[1.0, 2.0], [3.0, 4.0], [5.0, 6.0]], heading=[0.0, np.pi / 2, np.pi],
                     score=[0.2, 0.9, 0.5])
    x, used = encode_frame(spec, det, latest_heading_rad=np.array([np.pi, np.nan]),
                           report_age_s=np.array([0.5, np.nan]))
    assert used.tolist() == [1, 2]  # the two most probable
    np.testing.assert_allclose(x[:6], [-1, 0, 0.5, 0, 0, spec.max_age_s], atol=1e-12)
    np.testing.assert_allclose(x[6:11], [3, 4, 0, 1, 0.9], atol=1e-12)
    np.testing.assert_allclose(x[11:], [5, 6, -1, 0, 0.5], atol=1e-12)
    rel = EncodingSpec(n_agents=2, n_slots=2, relative_headings=True)
    xr, _ = encode_frame(rel, det, latest_heading_rad=np.array([np.pi, np.nan]), report_age_s=np.array([0.5, np.nan]))
    assert rel.n_inputs == 6 + 2 * 9
    # slot 0 holds the detection with heading pi/2: relative to agent 0 (pi) it is -pi/2; agent 1 unknown.
    np.testing.assert_allclose(xr[6:15], [3, 4, 0, 1, 0.9, 0, -1, 0, 0], atol=1e-12)
    with pytest.raises(ValueError, match="position"):
        encode_frame(spec, Detections(xywh=[[0, 0, 1, 1]]), np.zeros(2), np.zeros(2))


def test_import_lookalike_learn_does_not_import_torch():
    code = "import sys, lookalike.learn; print('torch' in sys.modules)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "False"
