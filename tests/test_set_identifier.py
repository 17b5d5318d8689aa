import json
import os

import numpy as np
import pytest

from lookalike.learn.set_data import SetBatchMaker, agent_tokens, detection_tokens
from lookalike.sim import simulate_robots
from lookalike.trackers import make_tracker
from lookalike.trackers.lstm import CheckpointError
from lookalike.trackers.set.network import NumpySetAssociator, SetWeights, load_set_weights, save_set_weights


def random_weights(seed=0, token=8, pair=12, memory=6):
    shapes = SetWeights({}, token, pair, memory).shapes()
    rng = np.random.default_rng(seed)
    return SetWeights({k: 0.5 * rng.normal(size=s) for k, s in shapes.items()}, token, pair, memory)


def random_frames(n_agents, n_dets, n_frames, seed=1):
    rng = np.random.default_rng(seed)
    heading = rng.uniform(-np.pi, np.pi, n_agents)
    heading[0] = np.nan  # one agent never heard from
    agents = agent_tokens(heading, rng.uniform(0, 3, n_agents))
    return [(agents, detection_tokens(rng.uniform(0, 5, (n_dets, 2)), rng.uniform(-3, 3, n_dets),
                                      rng.uniform(0.2, 1, n_dets))) for _ in range(n_frames)]


def run(net, frames, n_agents):
    net.reset(n_agents)
    return [net.step(a, d, 1 / 30) for a, d in frames]


def test_permuting_detections_or_agents_permutes_the_outputs():
    net = NumpySetAssociator(random_weights())
    n, k = 4, 6
    frames = random_frames(n, k, 5)
    base = run(net, frames, n)
    det_perm = np.random.default_rng(2).permutation(k)
    agent_perm = np.random.default_rng(3).permutation(n)
    permuted = run(net, [(a[agent_perm], d[det_perm]) for a, d in frames], n)
    for p0, p1 in zip(base, permuted):
        np.testing.assert_allclose(p1, p0[det_perm][:, list(agent_perm) + [n]], atol=1e-12)


@pytest.mark.parametrize(("n_agents", "n_dets"), [(1, 0), (1, 3), (7, 10), (12, 27)])
def test_any_team_size_and_detection_count(n_agents, n_dets):
    net = NumpySetAssociator(random_weights())
    for prob in run(net, random_frames(n_agents, n_dets, 3), n_agents):
        assert prob.shape == (n_dets, n_agents + 1)
        np.testing.assert_allclose(prob.sum(axis=1), 1.0)


def test_numpy_equals_torch_with_padded_slots():
    torch = pytest.importorskip("torch", reason="torch (the 'train' extra) is needed to compare against")
    from lookalike.learn.set_model import SetAssociator, SetSizes

    torch.manual_seed(0)
    model = SetAssociator(SetSizes(8, 12, 6))
    a, d, v, y, dt = SetBatchMaker(fixed=(3, 6, 1.5))(7, 2, 40)
    with torch.no_grad():
        logp, _ = model(torch.as_tensor(a, dtype=torch.float32), torch.as_tensor(d, dtype=torch.float32),
                        torch.as_tensor(v), dt)
    net = NumpySetAssociator(SetWeights(model.export(), 8, 12, 6))
    for b in range(2):
        net.reset(3)
        for t in range(a.shape[1]):
            prob = net.step(a[b, t], d[b, t][v[b, t]], dt)
            np.testing.assert_allclose(prob, logp[b, t][torch.as_tensor(v[b, t])].exp().numpy(), atol=1e-5)


def test_weights_round_trip_and_refusals(tmp_path):
    w = random_weights()
    path = save_set_weights(w, tmp_path / "set.npz")
    back = load_set_weights(path)
    for name, arr in w.arrays.items():
        np.testing.assert_allclose(back.arrays[name], arr, rtol=1e-6)
    meta = json.loads(path.with_suffix(".json").read_text())
    meta["pair"] = 99
    path.with_suffix(".json").write_text(json.dumps(meta))
    with pytest.raises(CheckpointError, match="shape"):
        load_set_weights(path)
    path.with_suffix(".json").write_text(json.dumps({"format": "something-else"}))
    with pytest.raises(CheckpointError, match="not a lookalike set associator"):
        load_set_weights(path)


@pytest.mark.parametrize(("n_agents", "n_slots"), [(2, 3), (4, 6)])
def test_registered_identifier_labels_a_simulated_sequence(tmp_path, n_agents, n_slots):
    from lookalike.learn.set_data import world

    weights = save_set_weights(random_weights(), tmp_path / "set.npz")
    tracker = make_tracker("set", n_agents=n_agents, n_slots=n_slots, weights=str(weights))
    seq = simulate_robots(world(n_agents, n_slots, 1.0), 30, 5)
    for frame in seq.frames():
        tracks = tracker.update(frame)
        labels = tracker.last_labels
        assert labels.shape == (len(frame.detections),)
        agents = labels[labels >= 0]
        assert len(set(agents)) == len(agents)  # one-to-one
        assert all(0 <= t.agent_id < n_agents for t in tracks)


def test_shipped_weights_load_for_sizes_never_trained_separately():
    from lookalike.learn.set_data import world
    from lookalike.trackers.set.network import SHIPPED_SET_WEIGHTS

    if not SHIPPED_SET_WEIGHTS.is_file():
        pytest.skip("no shipped set weights")
    tracker = make_tracker("set", n_agents=12, n_slots=14)
    seq = simulate_robots(world(12, 14, 2.0), 10, 3)
    for frame in seq.frames():
        tracker.update(frame)


def test_training_writes_loadable_weights_and_resumes(tmp_path):
    pytest.importorskip("torch", reason="training needs torch (the 'train' extra)")
    from dataclasses import replace

    from lookalike.learn.set_training import SetTrainConfig, train_set

    config = SetTrainConfig(token=8, pair=12, memory=6, n_max=3, batch_size=2, sequence_length=20, bptt=20, steps=2,
                            validation_sequences=1, validation_length=20, validation_every=1)
    first = train_set(config, tmp_path)
    assert first.steps == 2 and 0.0 <= first.best_success <= 1.0
    NumpySetAssociator(load_set_weights(first.weights_path))
    with pytest.raises(ValueError, match=r"other settings: pair 12 \(now 10\); run with the same settings"):
        train_set(replace(config, pair=10), tmp_path, resume=True)
    cooled = train_set(replace(config, steps=3, learning_rate=0.001), tmp_path, resume=True)  # one step more
    assert cooled.steps == 3 and [h["step"] for h in cooled.history] == [1, 2, 3]


def test_train_refuses_an_unknown_model_in_one_line(tmp_path):
    pytest.importorskip("torch", reason="training needs torch (the 'train' extra)")
    from typer.testing import CliRunner

    from lookalike.cli import app

    result = CliRunner().invoke(app, ["train", "--model", "nope", "-o", str(tmp_path)])
    assert result.exit_code == 2 and "--model" in result.output and "Traceback" not in result.output


def test_weights_save_killed_between_its_two_files_is_refused_not_mismatched(tmp_path, monkeypatch):
    path = save_set_weights(random_weights(seed=0), tmp_path / "set.npz")

    def killed(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(np, "savez_compressed", killed)  # the .json of the new weights is written, then the kill
    with pytest.raises(KeyboardInterrupt):
        save_set_weights(random_weights(seed=1, pair=10), path)
    monkeypatch.undo()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["set.json", "set.npz"]
    with pytest.raises(CheckpointError, match=r"set\.npz and .*set\.json are not one pair"):
        load_set_weights(path)
    save_set_weights(random_weights(seed=1, pair=10), path)  # saved again: one pair
    assert load_set_weights(path).pair == 10
    other = save_set_weights(random_weights(seed=2), tmp_path / "other.npz")
    other.with_suffix(".json").replace(path.with_suffix(".json"))  # files of two saves put side by side
    with pytest.raises(CheckpointError, match="not one pair"):
        load_set_weights(path)


def test_copied_weights_replace_the_old_pair_whole_or_are_refused(tmp_path, monkeypatch):
    from lookalike import _files
    from lookalike.trackers.parts import weights_io

    old = save_set_weights(random_weights(seed=0), tmp_path / "old" / "set.npz")
    new = save_set_weights(random_weights(seed=1, pair=10), tmp_path / "new.npz")
    keep = tmp_path / "old" / "kept.npz"
    os.link(old, keep)  # a second name of the old file: written in place, it would change too
    writes = []

    def killed_at_the_npz(target, write):
        writes.append(target.name)
        if target.suffix == ".npz":
            raise KeyboardInterrupt
        real(target, write)

    real = _files.replace_file
    monkeypatch.setattr(_files, "replace_file", killed_at_the_npz)
    with pytest.raises(KeyboardInterrupt):
        weights_io.copy_weights(new, old)
    monkeypatch.undo()
    assert writes == ["set.json", "set.npz"]
    with pytest.raises(CheckpointError, match="not one pair"):
        load_set_weights(old)
    weights_io.copy_weights(new, old)
    assert load_set_weights(old).pair == 10 and keep.read_bytes() != old.read_bytes()
    assert sorted(p.name for p in old.parent.iterdir()) == ["kept.npz", "set.json", "set.npz"]


@pytest.mark.parametrize("mask", [0o022, 0o077])
def test_saved_weights_follow_the_umask(tmp_path, mask):
    """They were made with mkstemp's mode 0600 whatever the umask (unreadable to the group, shipped or not)."""
    import stat

    old = os.umask(mask)
    try:
        path = save_set_weights(random_weights(), tmp_path / "set.npz")
    finally:
        os.umask(old)
    for p in (path, path.with_suffix(".json")):
        assert stat.S_IMODE(p.stat().st_mode) == 0o666 & ~mask
