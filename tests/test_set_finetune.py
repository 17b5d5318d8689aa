"""Fine-tuning options of the set associator's training: focus teams, swaps that end, init weights."""

import numpy as np
import pytest

from lookalike.learn.set_data import SetBatchMaker, TeamSizes
from lookalike.learn.set_numpy import SetWeights


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


def test_training_starts_from_init_weights(tmp_path):
    pytest.importorskip("torch", reason="training needs torch (the 'train' extra)")
    from lookalike.learn.set_numpy import load_set_weights
    from lookalike.learn.set_training import SetTrainConfig, train_set

    shapes = SetWeights({}, 8, 12, 6).shapes()
    rng = np.random.default_rng(0)
    init = SetWeights({k: 0.3 * rng.normal(size=s) for k, s in shapes.items()}, 8, 12, 6)
    config = SetTrainConfig(token=8, pair=12, memory=6, n_max=2, batch_size=1, sequence_length=10, bptt=10, steps=0,
                            validation_sequences=1, validation_length=10)
    result = train_set(config, tmp_path, init=init)  # no step: the saved weights are the initial ones
    back = load_set_weights(result.weights_path)
    for name, arr in init.arrays.items():
        np.testing.assert_allclose(back.arrays[name], arr, rtol=1e-5, atol=1e-6)
    with pytest.raises(ValueError, match="widths"):
        train_set(SetTrainConfig(token=8, pair=10, memory=6, steps=0), tmp_path / "other", init=init)


def test_focus_teams_of_a_run_weight_the_draws():
    from lookalike.learn.set_finetune import FINETUNE_CONFIG

    sizes = FINETUNE_CONFIG.batch_maker().sizes
    draws = [sizes.draw(np.random.default_rng(s)) for s in range(600)]
    small, mid, big = (draws.count(t) for t in ((2, 3, 0.5), (3, 5, 0.8), (7, 10, 1.5)))
    assert small > mid > big > 0  # weighted 3 : 2 : 1
    assert sum(1 for n, _, _ in draws if n >= 8) > 0  # the other batches still span every team size


def test_snapshot_choice_needs_every_tuning_team_at_the_baseline():
    from lookalike.bench.set_select import choose

    base = {"m3n2": 98.0, "m5n3": 97.0}
    rows = {"a": {"m3n2": 99.0, "m5n3": 96.9},  # best small team, but below the baseline elsewhere
            "b": {"m3n2": 98.5, "m5n3": 97.0},
            "c": {"m3n2": 98.495, "m5n3": 98.0}}  # a tie on M=3, N=2 within 0.01: the better mean wins
    assert choose(rows, base) == "c"
    assert choose({"a": rows["a"]}, base) is None
