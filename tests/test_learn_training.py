import numpy as np
import pytest

from lookalike.types import Beacons, Detections, Frame

torch = pytest.importorskip("torch", reason="training needs torch (the 'train' extra)")

from lookalike.learn.training import TrainConfig, plot_log, train  # noqa: E402
from lookalike.trackers.lstm.encoding import EncodingSpec  # noqa: E402
from tests.learn_oracle import frames_to_arrays  # noqa: E402


def toy_frames(seed: int, n_frames: int):
    """Two agents whose visual heading matches their reported heading; one false positive."""
    rng = np.random.default_rng(seed)
    heading = rng.uniform(-np.pi, np.pi, 2)
    frames = []
    for k in range(n_frames):
        heading = heading + rng.normal(0, 0.05, 2)
        pos = rng.uniform(0, 5, (3, 2))
        vis = np.concatenate([heading + rng.normal(0, 0.2, 2), rng.uniform(-np.pi, np.pi, 1)])
        det = Detections(position=pos, heading=vis, score=[0.9, 0.9, 0.5], label=[0, 1, -1])
        b = Beacons(agent_id=[0, 1], t_sent=[k / 30] * 2, t_received=[k / 30] * 2, heading=heading)
        frames.append(Frame(index=k, time=k / 30, detections=det, beacons=b))
    return frames


def toy_sampler(seed, n_frames, rng):
    return frames_to_arrays(EncodingSpec(2, 3, relative_headings=True), toy_frames(seed, n_frames), rng)


def _config(**kw):
    base = dict(n_agents=2, n_slots=3, hidden=16, num_layers=1, bptt=15, sequence_length=30, batch_size=4,
                steps=30, validation_every=10, validation_sequences=4, learning_rate=0.01, patience=100)
    base.update(kw)
    return TrainConfig(**base)


def test_tiny_training_learns_and_writes_outputs(tmp_path):
    torch.set_num_threads(1)
    result = train(_config(), toy_sampler, tmp_path)
    losses = [h["loss"] for h in result.history]
    assert losses[-1] < losses[0]
    assert result.best_success > 0.6  # chance is about 1/3
    assert result.weights_path.is_file() and result.weights_path.with_suffix(".json").is_file()
    assert plot_log(result.log_path, tmp_path / "log.png").stat().st_size > 0


def test_training_is_deterministic_for_a_seed(tmp_path):
    torch.set_num_threads(1)
    a = train(_config(steps=10, validation_every=5), toy_sampler, tmp_path / "a")
    b = train(_config(steps=10, validation_every=5), toy_sampler, tmp_path / "b")
    assert [h["loss"] for h in a.history] == [h["loss"] for h in b.history]


def test_resume_continues_where_it_stopped(tmp_path):
    torch.set_num_threads(1)
    train(_config(steps=10, validation_every=5), toy_sampler, tmp_path)
    resumed = train(_config(steps=10, validation_every=5), toy_sampler, tmp_path, resume=True)
    assert resumed.steps == 10 and len(resumed.history) == 2  # nothing left to do
    with pytest.raises(ValueError, match=r"other settings: steps 10 \(now 20\); run with the same settings"):
        train(_config(steps=20, validation_every=5), toy_sampler, tmp_path, resume=True)


def test_an_interrupted_checkpoint_write_keeps_the_previous_checkpoint(tmp_path, monkeypatch):
    """Ctrl-C while the checkpoint was written left it cut short, and ``--resume`` then ended in a torch
    traceback; now the previous checkpoint stays whole and a damaged one is refused in one line naming it."""
    torch.set_num_threads(1)
    train(_config(steps=5, validation_every=5), toy_sampler, tmp_path)
    checkpoint = tmp_path / "checkpoint.pt"
    before = checkpoint.read_bytes()

    def cut_short(state, f, *args, **kwargs):
        with open(f, "wb") as fh:
            fh.write(b"PK\x03\x04 half a checkpoint")
        raise KeyboardInterrupt

    monkeypatch.setattr(torch, "save", cut_short)
    with pytest.raises(KeyboardInterrupt):
        train(_config(steps=10, validation_every=5), toy_sampler, tmp_path, resume=False)
    monkeypatch.undo()
    assert checkpoint.read_bytes() == before
    assert sorted(p.name for p in tmp_path.iterdir() if p.name.startswith(".")) == []
    checkpoint.write_bytes(before[: len(before) // 2])
    with pytest.raises(ValueError, match="checkpoint.pt: not a readable training checkpoint .*drop --resume"):
        train(_config(steps=5, validation_every=5), toy_sampler, tmp_path, resume=True)


def test_batches_made_in_worker_processes_train_identically(tmp_path):
    from lookalike.parallel import JobPool

    torch.set_num_threads(1)
    serial = train(_config(steps=6, validation_every=3), toy_sampler, tmp_path / "a")
    with JobPool(2) as pool:
        parallel = train(_config(steps=6, validation_every=3), toy_sampler, tmp_path / "b", pool=pool)
    assert [h["loss"] for h in serial.history] == [h["loss"] for h in parallel.history]


def test_training_can_start_from_exported_weights(tmp_path):
    from lookalike.learn.model import AssociationNet
    from lookalike.trackers.lstm.checkpoint import load_weights

    torch.set_num_threads(1)
    first = train(_config(steps=10, validation_every=10), toy_sampler, tmp_path / "a")
    weights = load_weights(first.weights_path)
    net = AssociationNet(weights.spec, 16, 1)
    net.load_exported(weights)
    again = net.export()
    for name in ("head_weight", "head_bias", "input_mean", "input_std"):
        np.testing.assert_array_equal(getattr(again, name), getattr(weights, name))
    warm = train(_config(steps=1, validation_every=1, learning_rate=1e-12), toy_sampler, tmp_path / "b", init=weights)
    assert warm.best_success == pytest.approx(first.best_success, abs=1e-9)
    with pytest.raises(ValueError, match="do not fit"):
        AssociationNet(weights.spec, 8, 1).load_exported(weights)


def test_noise_mix_keeps_identity_swaps_for_our_protocol():
    from lookalike.learn.paper_protocol import NoiseMixSampler, noise_worlds
    from lookalike.learn.sim_data import WorldMixSampler, make_sim_sampler

    worlds = noise_worlds("m3n2", "mix")
    plain = NoiseMixSampler(worlds, EncodingSpec(2, 3, relative_headings=False))
    mixed = WorldMixSampler(tuple(make_sim_sampler(w, False) for w in worlds))
    swapped = WorldMixSampler(tuple(make_sim_sampler(w, False, swap_prob=1.0) for w in worlds))
    differs = 0
    for seed in range(3):
        x0, y0 = plain(seed, 300, np.random.default_rng([seed, 1]))
        x1, y1 = mixed(seed, 300, np.random.default_rng([seed, 1]))
        assert np.array_equal(x0, x1) and np.array_equal(y0, y1)  # without swaps: the same sequences
        differs += not np.array_equal(swapped(seed, 300, np.random.default_rng([seed, 1]))[1], y0)
    assert differs > 0


def test_a_run_killed_while_rewriting_its_log_keeps_the_earlier_log(tmp_path):
    """The log was rewritten in place at every validation: a kill then left it cut short, the earlier rows lost."""
    from lookalike.learn.training import _write_log

    class Interrupting:
        def __str__(self) -> str:
            raise KeyboardInterrupt

    log = tmp_path / "training_log.csv"
    _write_log(log, [{"step": 1, "loss": 0.5, "val_success": 0.2}])
    before = log.read_bytes()
    with pytest.raises(KeyboardInterrupt):
        _write_log(log, [{"step": 1, "loss": Interrupting(), "val_success": 0.2}])
    assert log.read_bytes() == before and [p.name for p in tmp_path.iterdir()] == ["training_log.csv"]
    png = plot_log(log, tmp_path / "training_log.png")
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["training_log.csv", "training_log.png"]
