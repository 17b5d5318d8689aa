"""Fine-tuning options of the set associator's training: focus teams, swaps that end, init weights."""

import numpy as np
import pytest

from lookalike.learn.set_data import SetBatchMaker, TeamSizes
from lookalike.learn.set_numpy import SetWeights, load_set_weights, save_set_weights


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


def test_the_second_stage_draws_more_small_teams_and_swaps():
    from lookalike.learn.set_finetune import FINETUNE2_CONFIG, STAGES

    assert STAGES[2] is FINETUNE2_CONFIG
    sizes = FINETUNE2_CONFIG.batch_maker().sizes
    draws = [sizes.draw(np.random.default_rng(s)) for s in range(600)]
    small, mid, big = (draws.count(t) for t in ((2, 3, 0.5), (3, 5, 0.8), (7, 10, 1.5)))
    assert small > big > mid > 0  # weighted 4 : 1 : 2
    assert sum(1 for n, _, _ in draws if n >= 8) > 0
    assert FINETUNE2_CONFIG.swap_prob > STAGES[1].swap_prob


def test_stage2_choice_weighs_small_team_then_recovery_and_ships_only_when_better():
    from lookalike.bench.set_select import better_than, choose_stage2

    base = {"m3n2": 98.0, "m5n3": 97.0, "rec_m3n2": 0.5, "rec_m5n3": 0.5, "worst_m3n2": 1.0, "worst_m5n3": 1.0}
    rows = {"slow": {**base, "m3n2": 99.0, "rec_m3n2": 0.6},  # best small team, but recovers slower
            "low": {**base, "m3n2": 98.9, "m5n3": 96.6},  # more than 0.3 points lost elsewhere
            "a": {**base, "m3n2": 98.5, "rec_m3n2": 0.4},
            "b": {**base, "m3n2": 98.46, "rec_m3n2": 0.3},  # within 0.05 of the best: faster recovery wins
            "never": {**base, "m3n2": 98.6, "worst_m5n3": float("inf")}}
    assert choose_stage2(rows, base) == "b"
    assert choose_stage2({"slow": rows["slow"], "low": rows["low"]}, base) is None
    assert better_than(rows["b"], base)
    assert not better_than({**base, "m3n2": 98.04, "rec_m3n2": 0.48}, base)
    assert better_than({**base, "rec_m3n2": 0.4}, base)


def test_stage2_candidates_are_step_multiples_and_their_late_mean(tmp_path):
    from lookalike.bench.set_select import _candidates

    shapes = SetWeights({}, 8, 12, 6).shapes()
    for k in (50, 100, 200, 300, 400):
        w = SetWeights({n: np.full(s, float(k)) for n, s in shapes.items()}, 8, 12, 6)
        save_set_weights(w, tmp_path / f"set_step{k}.npz")
    got = _candidates(tmp_path, 100, 300)
    assert [p.name for p in got] == ["set_step100.npz", "set_step200.npz", "set_step300.npz", "set_step400.npz",
                                     "set_avg.npz"]
    mean = load_set_weights(got[-1])
    assert all(np.allclose(a, 350.0) for a in mean.arrays.values())
    assert _candidates(tmp_path, 100, 400)[-1].name == "set_step400.npz"  # one late snapshot: no mean


def test_tuning_recovery_is_bench_recoverys_measure():
    from lookalike.bench.experiments import recovery_rows
    from lookalike.bench.set_select import set_recovery_s
    from lookalike.learn.set_tracker import SHIPPED_SET_WEIGHTS
    from lookalike.sim import preset, simulate_robots

    seq = simulate_robots(preset("m3n2"), 300, 55_001)
    mine = set_recovery_s(SHIPPED_SET_WEIGHTS, seq, swap_at_s=2.0, swap_s=3.0)
    row = recovery_rows(["m3n2"], ["set"], 1, 300, 2.0, 3.0, seed=55_001)[0]
    assert round(mine, 2) == row["Recovery, mean (s)"]


def test_the_noise_mix_draws_both_noise_models_per_sequence():
    from lookalike.learn.set_finetune import FINETUNE4_CONFIG, STAGES
    from lookalike.sim import noise_sensor

    assert STAGES[4] is FINETUNE4_CONFIG
    maker = FINETUNE4_CONFIG.batch_maker()
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
    from lookalike.learn.set_finetune import FINETUNE16_CONFIG, STAGES

    assert STAGES[16] is FINETUNE16_CONFIG and FINETUNE16_CONFIG.silent_swap_prob > 0
    assert FINETUNE16_CONFIG.batch_maker().silent_swap_prob == FINETUNE16_CONFIG.silent_swap_prob
    plain = SetBatchMaker(fixed=(3, 5, 0.5), swap_prob=1.0, swap_ends=1.0)(3, 2, 240)
    silent = SetBatchMaker(fixed=(3, 5, 0.5), swap_prob=1.0, swap_ends=1.0, silent_swap_prob=1.0)(3, 2, 240)
    np.testing.assert_array_equal(plain[1], silent[1])  # the same detections
    assert (plain[0] != silent[0]).any()  # fewer reports: other agent tokens
    np.testing.assert_array_equal(SetBatchMaker(fixed=(3, 5, 0.5), swap_prob=1.0, swap_ends=1.0,
                                                silent_swap_prob=0.0)(3, 2, 240)[0], plain[0])  # off: as before
    with pytest.raises(ValueError, match="silent_swap_prob"):
        SetBatchMaker(silent_swap_prob=-0.1)


def test_stage4_candidates_and_choice(tmp_path):
    from lookalike.bench.set_select_stage4 import BASELINE, choose_stage4, stage4_candidates

    for k in (25, 500, 750, 1000):
        (tmp_path / f"set_step{k}.npz").write_bytes(b"")
    names = list(stage4_candidates(tmp_path))
    assert names[0] == BASELINE and len(names) == 9  # shipped, steps 500 and 1000, each off / 1.5 / 1.0 rad
    assert stage4_candidates(tmp_path)["step1000,pair=1.5"][1] == {"pair_swap": 1.5}
    base = {"m3n2": 98.0, "m5n3": 97.0, "rec_m3n2": 0.4, "rec_m10n7": 0.6, "worst_m3n2": 1.0}
    rows = {BASELINE: base,
            "up": {**base, "m3n2": 98.06},  # M=3, N=2 gain alone
            "fast": {**base, "m3n2": 98.02, "rec_m10n7": 0.5},  # recovery gain (mean of the means 0.05 s lower)
            "lost": {**base, "m3n2": 98.3, "m5n3": 96.9},  # another team 0.1 points down
            "slow": {**base, "m3n2": 98.3, "rec_m3n2": 0.43},  # a set-up's recovery 0.03 s slower
            "same": {**base, "m3n2": 98.04, "rec_m10n7": 0.56}}  # neither gain large enough
    assert choose_stage4(rows) == "fast"  # within 0.05 points of "up" on M=3, N=2 and faster to recover
    del rows["fast"]
    assert choose_stage4(rows) == "up"
    assert choose_stage4({BASELINE: base, "same": rows["same"], "lost": rows["lost"]}) is None
