"""Training options of the set associator: focus teams, swaps that end, noise mixes, init weights."""

import numpy as np
import pytest

from lookalike.learn.set_data import SetBatchMaker, TeamSizes
from lookalike.trackers.set.network import SetWeights, load_set_weights


def test_focus_teams_are_drawn_and_checked():
    sizes = TeamSizes(focus=((2, 3, 0.5),), focus_prob=1.0)
    assert {sizes.draw(np.random.default_rng(s)) for s in range(5)} == {(2, 3, 0.5)}
    plain = TeamSizes()
    assert plain.draw(np.random.default_rng(1)) == TeamSizes(focus=((2, 3, 0.5),)).draw(np.random.default_rng(1))
    with pytest.raises(ValueError, match="focus"):
        TeamSizes(focus_prob=0.5)


def test_a_swap_that_must_end_leaves_the_last_seconds_alone():
    n_frames = 150  # 5 s at 30 Hz
    plain = SetBatchMaker(fixed=(3, 5, 0.5))(3, 2, n_frames)
    swapped = SetBatchMaker(fixed=(3, 5, 0.5), swap_prob=1.0, swap_s=(1.0, 2.0), swap_ends=2.0)(3, 2, n_frames)
    y0, y1 = plain[3], swapped[3]
    assert (y0 != y1).any()  # the labels of the swapped robots changed somewhere
    np.testing.assert_array_equal(y0[:, -30:], y1[:, -30:])  # but not in the last second


def _random_weights() -> SetWeights:
    """Small random set-associator weights (token 8, pair 12, memory 6) to start a training from."""
    rng = np.random.default_rng(0)
    return SetWeights({k: 0.3 * rng.normal(size=s) for k, s in SetWeights({}, 8, 12, 6).shapes().items()}, 8, 12, 6)


def test_training_starts_from_init_weights(tmp_path):
    pytest.importorskip("torch", reason="training needs torch (the 'train' extra)")
    from lookalike.learn.set_training import SetTrainConfig, train_set

    init = _random_weights()
    config = SetTrainConfig(token=8, pair=12, memory=6, n_max=2, batch_size=1, sequence_length=10, bptt=10, steps=0,
                            validation_sequences=1, validation_length=10)
    result = train_set(config, tmp_path, init=init)  # no step: the saved weights are the initial ones
    back = load_set_weights(result.weights_path)
    for name, arr in init.arrays.items():
        np.testing.assert_allclose(back.arrays[name], arr, rtol=1e-5, atol=1e-6)
    with pytest.raises(ValueError, match="widths"):
        train_set(SetTrainConfig(token=8, pair=10, memory=6, steps=0), tmp_path / "other", init=init)


def test_training_only_the_named_layers_leaves_the_others_as_they_were(tmp_path):
    pytest.importorskip("torch", reason="training needs torch (the 'train' extra)")
    from lookalike.learn.set_training import SetTrainConfig, train_set

    init = _random_weights()
    config = SetTrainConfig(token=8, pair=12, memory=6, n_max=2, batch_size=2, sequence_length=20, bptt=20, steps=2,
                            validation_sequences=1, validation_length=20, validation_every=1, trainable=("gru",),
                            learning_rate=0.01)
    back = load_set_weights(train_set(config, tmp_path, init=init).weights_path)
    moved = {name for name, arr in init.arrays.items() if not np.allclose(back.arrays[name], arr, atol=1e-6)}
    assert moved and all(name.startswith("gru") for name in moved)
    with pytest.raises(ValueError, match="no parameter"):
        train_set(SetTrainConfig(token=8, pair=12, memory=6, steps=0, trainable=("lstm",)), tmp_path / "x", init=init)


def test_the_noise_mix_draws_both_noise_models_per_sequence():
    from lookalike.sim import noise_sensor

    maker = SetBatchMaker(noises=("ours", "paper"))
    assert set(maker.noises) == {"ours", "paper"}
    base = SetBatchMaker(fixed=(2, 3, 0.5)).world_of
    from lookalike.learn.set_data import world

    cfg = world(2, 3, 0.5)
    assert base(cfg, 7) is cfg  # no noise mix: the default world
    sensors = {maker.world_of(cfg, s).sensor for s in range(40)}
    assert sensors == {noise_sensor(n, cfg.sensor) for n in ("ours", "paper")}
    assert all(s.fp_per_frame == 0.5 for s in sensors)  # the team's clutter is kept
    # one model alone (the default world's, "ours") makes the batches made without the option
    plain = SetBatchMaker(fixed=(2, 3, 0.5))(5, 2, 60)
    ours = SetBatchMaker(fixed=(2, 3, 0.5), noises=("ours",))(5, 2, 60)
    for a, b in zip(plain[:4], ours[:4]):
        np.testing.assert_array_equal(a, b)
    paper = SetBatchMaker(fixed=(2, 3, 0.5), noises=("paper",))(5, 2, 60)
    assert not np.array_equal(plain[1], paper[1])  # other position noise, other detections
    with pytest.raises(ValueError, match="noise"):
        SetBatchMaker(noises=("loud",))


def test_close_heading_swaps_pick_the_pair_of_closest_headings():
    from lookalike.learn.set_data import closest_headings, world
    from lookalike.sim import simulate_arrays

    arrays = simulate_arrays(world(4, 6, 0.5), 90, 11)
    h = arrays.true_heading[30]
    i, j = closest_headings(arrays, arrays.time[30])
    gap = lambda a, b: abs(np.angle(np.exp(1j * (h[a] - h[b]))))  # noqa: E731
    assert i < j and all(gap(i, j) <= gap(a, b) for a in range(4) for b in range(a + 1, 4))
    plain = SetBatchMaker(fixed=(4, 6, 0.5), swap_prob=1.0, swap_ends=1.0)(3, 2, 90)
    close = SetBatchMaker(fixed=(4, 6, 0.5), swap_prob=1.0, swap_ends=1.0, close_swap_prob=1.0)(3, 2, 90)
    assert plain[0].shape == close[0].shape and (plain[3] != close[3]).any()  # other pairs swapped
    with pytest.raises(ValueError, match="close_swap_prob"):
        SetBatchMaker(close_swap_prob=1.5)


def test_silent_swaps_drop_one_pair_members_reports_near_the_swaps_end():
    plain = SetBatchMaker(fixed=(3, 5, 0.5), swap_prob=1.0, swap_ends=1.0)(3, 2, 240)
    silent = SetBatchMaker(fixed=(3, 5, 0.5), swap_prob=1.0, swap_ends=1.0, silent_swap_prob=1.0)(3, 2, 240)
    np.testing.assert_array_equal(plain[1], silent[1])  # the same detections
    assert (plain[0] != silent[0]).any()  # fewer reports: other agent tokens
    np.testing.assert_array_equal(SetBatchMaker(fixed=(3, 5, 0.5), swap_prob=1.0, swap_ends=1.0,
                                                silent_swap_prob=0.0)(3, 2, 240)[0], plain[0])  # off: as before
    with pytest.raises(ValueError, match="silent_swap_prob"):
        SetBatchMaker(silent_swap_prob=-0.1)


