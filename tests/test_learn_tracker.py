import numpy as np
import pytest

from lookalike.trackers import make_tracker
from lookalike.trackers.lstm import CheckpointError, EncodingSpec, NetworkWeights, save_weights
from lookalike.trackers.lstm.tracker import LstmIdentifier
from lookalike.trackers.parts.agents import BeaconMemory, decode
from lookalike.types import Beacons, Detections, Frame, TrackStatus


def _random_weights(tmp_path, n_agents=2, n_slots=3, hidden=8, layers=2, seed=0):
    spec = EncodingSpec(n_agents, n_slots)
    rng = np.random.default_rng(seed)
    g = 4 * hidden
    layer_list = [
        {"w_ih": rng.normal(0, 0.3, (g, spec.n_inputs if i == 0 else hidden)), "w_hh": rng.normal(0, 0.3, (g, hidden)),
         "b_ih": np.zeros(g), "b_hh": np.zeros(g)}
        for i in range(layers)
    ]
    w = NetworkWeights(spec, "lstm", hidden, layer_list, rng.normal(0, 0.3, (n_slots * (n_agents + 1), hidden)),
                       np.zeros(n_slots * (n_agents + 1)), np.zeros(spec.n_inputs), np.ones(spec.n_inputs))
    return save_weights(w, tmp_path / "w")


def _frame(k, positions, beacons=None):
    pos = np.asarray(positions, float).reshape(-1, 2)
    det = Detections(position=pos, heading=np.zeros(len(pos)), score=np.full(len(pos), 0.9))
    return Frame(index=k, time=k / 30, detections=det, beacons=beacons or Beacons.empty())


def test_lstm_tracker_labels_every_detection(tmp_path):
    path = _random_weights(tmp_path)
    tracker = make_tracker("lstm", n_agents=2, n_slots=3, weights=str(path))
    beacons = Beacons(agent_id=[0, 1], t_sent=[0, 0], t_received=[0.01, 0.02], heading=[0.1, 2.0])
    out = tracker.update(_frame(0, [[1, 0], [2, 1], [3, 3], [4, 4]], beacons))
    assert tracker.last_labels.shape == (4,)
    assert set(tracker.last_labels.tolist()) <= {-1, 0, 1}
    labelled = tracker.last_labels[tracker.last_labels >= 0]
    assert len(labelled) == len(set(labelled.tolist()))  # one-to-one decoding
    assert all(t.agent_id == t.track_id - 1 for t in out)
    assert tracker.update(_frame(1, [])) == [] or all(
        t.status is TrackStatus.LOST for t in tracker.update(_frame(2, [])))


def test_wrong_setup_is_refused(tmp_path):
    path = _random_weights(tmp_path)
    with pytest.raises(CheckpointError, match="n_agents=2, but 3"):
        LstmIdentifier(LstmIdentifier.Config(n_agents=3, n_slots=3, weights=str(path)))
    with pytest.raises(CheckpointError, match="no shipped weights for M=4, N=9"):
        LstmIdentifier(LstmIdentifier.Config(n_agents=9, n_slots=4))


def test_a_file_that_is_not_exported_weights_is_named_as_given(tmp_path):
    """A training run's checkpoint.pt was reported as 'checkpoint.npz: expected checkpoint.npz and checkpoint.json',
    naming a file the user never gave; a missing .npz and a missing .json are told apart."""
    from lookalike.trackers.lstm import load_weights

    path = _random_weights(tmp_path)
    (tmp_path / "checkpoint.pt").write_bytes(b"torch checkpoint")
    with pytest.raises(CheckpointError, match=r"checkpoint.pt: not exported weights .*model.npz"):
        load_weights(tmp_path / "checkpoint.pt")
    with pytest.raises(CheckpointError, match=r"other.npz: no such file"):
        load_weights(tmp_path / "other.npz")
    path.with_suffix(".json").unlink()
    with pytest.raises(CheckpointError, match=rf"{path.with_suffix('.json').name}: missing"):
        load_weights(path)


def test_beacon_memory_keeps_newest_and_ignores_late_reports():
    mem = BeaconMemory(2)
    mem.add(Frame(0, 0.0, beacons=Beacons(agent_id=[0], t_sent=[1.0], t_received=[1.1], heading=[0.5])))
    mem.add(Frame(1, 1.2, beacons=Beacons(agent_id=[0, 0], t_sent=[0.5, 0.9], t_received=[1.15, 1.19], heading=[9, 9])))
    assert mem.heading[0] == 0.5 and np.isnan(mem.heading[1])
    np.testing.assert_allclose(mem.age(1.5), [0.5, np.nan])


def test_decode_argmax_and_one_to_one():
    p = np.array([[0.6, 0.3, 0.1], [0.7, 0.2, 0.1], [0.1, 0.1, 0.8]])
    labels, _ = decode(p, np.arange(3), 3, one_to_one=False)
    assert labels.tolist() == [0, 0, -1]
    labels, conf = decode(p, np.arange(3), 3, one_to_one=True)
    assert labels.tolist() == [1, 0, -1]  # 0.3*0.7 > 0.6*0.2
    assert conf.tolist() == [0.3, 0.7, 0.8]
