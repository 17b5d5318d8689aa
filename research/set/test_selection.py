"""Tests of the selection stages that chose set's weights and options (research code, not the package).

They set options the current identifier no longer has: they ran in tests/ at commit c7fe8f3, where they still
run (research/set/README.md); kept here as the record of each stage's rule.
"""

import numpy as np

from lookalike.learn.set_numpy import SetWeights, load_set_weights, save_set_weights
from lookalike.learn.set_tracker import SetIdentifier
from lookalike.trackers import make_tracker


def test_focus_teams_of_a_run_weight_the_draws():
    from set_finetune import FINETUNE_CONFIG

    sizes = FINETUNE_CONFIG.batch_maker().sizes
    draws = [sizes.draw(np.random.default_rng(s)) for s in range(600)]
    small, mid, big = (draws.count(t) for t in ((2, 3, 0.5), (3, 5, 0.8), (7, 10, 1.5)))
    assert small > mid > big > 0  # weighted 3 : 2 : 1
    assert sum(1 for n, _, _ in draws if n >= 8) > 0  # the other batches still span every team size



def test_snapshot_choice_needs_every_tuning_team_at_the_baseline():
    from set_select import choose

    base = {"m3n2": 98.0, "m5n3": 97.0}
    rows = {"a": {"m3n2": 99.0, "m5n3": 96.9},  # best small team, but below the baseline elsewhere
            "b": {"m3n2": 98.5, "m5n3": 97.0},
            "c": {"m3n2": 98.495, "m5n3": 98.0}}  # a tie on M=3, N=2 within 0.01: the better mean wins
    assert choose(rows, base) == "c"
    assert choose({"a": rows["a"]}, base) is None



def test_the_second_stage_draws_more_small_teams_and_swaps():
    from set_finetune import FINETUNE2_CONFIG, STAGES

    assert STAGES[2] is FINETUNE2_CONFIG
    sizes = FINETUNE2_CONFIG.batch_maker().sizes
    draws = [sizes.draw(np.random.default_rng(s)) for s in range(600)]
    small, mid, big = (draws.count(t) for t in ((2, 3, 0.5), (3, 5, 0.8), (7, 10, 1.5)))
    assert small > big > mid > 0  # weighted 4 : 1 : 2
    assert sum(1 for n, _, _ in draws if n >= 8) > 0
    assert FINETUNE2_CONFIG.swap_prob > STAGES[1].swap_prob



def test_stage2_choice_weighs_small_team_then_recovery_and_ships_only_when_better():
    from set_select import better_than, choose_stage2

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
    from set_select import _candidates

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
    from set_select import set_recovery_s

    from lookalike.bench.experiments import recovery_runs
    from lookalike.learn.set_tracker import SHIPPED_SET_WEIGHTS
    from lookalike.sim import preset, simulate_robots

    seq = simulate_robots(preset("m3n2"), 300, 55_001)
    mine = set_recovery_s(SHIPPED_SET_WEIGHTS, seq, swap_at_s=2.0, swap_s=3.0)
    row = recovery_runs(["m3n2"], ["set"], 1, 300, 2.0, 3.0, seed=55_001)[0][0]
    assert round(mine, 2) == row["Recovery, mean (s)"]



def test_stage4_candidates_and_choice(tmp_path):
    from set_select_stage4 import BASELINE, choose_stage4, stage4_candidates

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



def test_stage3_choice_needs_the_small_team_up_and_nothing_else_down():
    from set_select import choose_stage3

    base = {"m3n2": 98.0, "m5n3": 97.0, "rec_m3n2": 0.3, "worst_m3n2": 1.0}
    rows = {"base": base,
            "a": {**base, "m3n2": 98.3, "m5n3": 96.9},  # best small team, but another team lost 0.1
            "b": {**base, "m3n2": 98.2, "rec_m3n2": 0.31},
            "c": {**base, "m3n2": 98.18, "rec_m3n2": 0.2},  # within 0.05 of b and faster to recover
            "slow": {**base, "m3n2": 98.5, "rec_m3n2": 0.4},
            "small": {**base, "m3n2": 98.05}}  # not 0.1 points up
    assert choose_stage3(rows, "base") == "c"
    assert choose_stage3({"base": base, "small": rows["small"], "slow": rows["slow"]}, "base") is None



def test_stage5_candidates_and_choice():
    from set_select_options import STAGE5_BASELINE, stage5_candidates
    from set_select_stage4 import choose_stage4

    cands = stage5_candidates()
    assert STAGE5_BASELINE in cands and cands[STAGE5_BASELINE][1] == {"fp_prior_ref": None}
    assert all(o["fp_prior_ref"] is None or o["fp_prior_ref"] > 0 for _, o in cands.values())
    base = {"m3n2": 98.0, "m5n3": 98.0, "rec_m3n2": 0.3, "worst_m3n2": 1.0}
    rows = {STAGE5_BASELINE: base, "up": {**base, "m3n2": 98.06}, "down": {**base, "m3n2": 98.2, "m5n3": 97.9}}
    assert choose_stage4(rows, STAGE5_BASELINE) == "up"



def test_exchange_stages_candidates():
    from set_select_options import EXCHANGE_BASELINE, exchange_candidates

    for stage, memory, fresh in ((6, None, None), (7, 1.0, None), (8, 1.0, 0.6)):
        cands = exchange_candidates(stage)
        assert cands[EXCHANGE_BASELINE][1]["exchange_llr"] is None
        assert all(o["exchange_memory_s"] == memory and o["exchange_fresh_s"] == fresh for _, o in cands.values())
        assert all(o["exchange_llr"] is None or o["exchange_llr"] > 0 for _, o in cands.values())

    from set_select_options import stage9_candidates

    options = stage9_candidates()["exchange=8.0,max_agents=7"][1]
    assert options["exchange_llr"] == 8.0 and options["exchange_max_agents"] == 7



def test_stage10_candidates():
    from set_select_options import STAGE10_BASELINE, stage_candidates

    cands, baseline = stage_candidates(10)
    assert baseline == STAGE10_BASELINE and cands[baseline][1] == {"jump_pair_s": None}
    assert {o["jump_pair_s"] for _, o in cands.values()} == {None, 1.0}



def test_stage12_to_15_candidates_and_the_guard():
    from set_select_options import stage_candidates
    from set_select_stage4 import passes_guard

    cands, baseline = stage_candidates(12)
    before = {"exchange_tight_agents": None, "jump_silent": False, "exchange_fresh_s": 0.6}  # before stage 14
    assert cands[baseline][1] == {"exchange_accel": 0.1, "exchange_lag_s": 0.4, **before}  # its detector
    cands, baseline = stage_candidates(13)
    assert cands[baseline][1] == before
    assert {o.get("exchange_step_rad") for _, o in cands.values()} == {None, 0.08, 0.12}
    cands, baseline = stage_candidates(14)
    before15 = {"jump_silent": False, "exchange_fresh_s": 0.6}  # the identifier shipped before stage 15
    assert cands[baseline][1] == before and {"exchange_tight_agents": 5, **before15} in [o for _, o in cands.values()]
    cands, baseline = stage_candidates(15)
    assert cands[baseline][1] == before15
    assert [o for n, (_, o) in cands.items() if n != baseline] == [
        {"jump_silent": True, "exchange_fresh_s": 0.6}, {"jump_silent": True, "exchange_fresh_s": None}]
    shipped = SetIdentifier.Config()  # the fifteenth stage's choice
    assert shipped.jump_silent and shipped.exchange_fresh_s is None
    base = {"m3n2": 98.9, "m5n3": 98.2, "rec_m3n2": 0.1, "worst_m3n2": 0.3}
    assert passes_guard({**base, "m3n2": 98.86, "rec_m3n2": 0.12}, base)
    assert not passes_guard({**base, "m3n2": 98.84}, base)  # a team more than 0.05 points below
    assert not passes_guard({**base, "rec_m3n2": 0.13}, base)  # recovery more than 0.02 s slower



def test_stage16_candidates_are_the_snapshots_at_its_steps(tmp_path):
    from set_select_options import STAGE16_BASELINE, stage_candidates

    from lookalike.learn.set_tracker import SHIPPED_SET_WEIGHTS

    for k in (25, 250, 400, 500):
        (tmp_path / f"set_step{k}.npz").write_bytes(b"")
    cands, baseline = stage_candidates(16, tmp_path)
    assert baseline == STAGE16_BASELINE and cands[baseline] == (SHIPPED_SET_WEIGHTS, {})
    assert {n: w for n, (w, _) in cands.items() if n != baseline} == {
        "step250": tmp_path / "set_step250.npz", "step500": tmp_path / "set_step500.npz"}



def test_stage17_candidates_are_the_visual_detector_at_each_threshold_against_the_shipped_identifier():
    from set_select_options import STAGE16_BASELINE, stage_candidates

    cands, baseline = stage_candidates(17)
    assert baseline == STAGE16_BASELINE and cands[baseline][1] == {"visual_exchange": None}
    assert sorted(o["visual_exchange"] for n, (_, o) in cands.items() if n != baseline) == [8.0, 10.0, 12.0]
    assert {o["visual_memory_s"] for n, (_, o) in cands.items() if n != baseline} == {10.0}



def test_stage18_candidates_widen_the_visual_detectors_stale_reports_against_the_identifier_before_it():
    from set_select_options import STAGE16_BASELINE, stage_candidates

    cands, baseline = stage_candidates(18)
    assert baseline == STAGE16_BASELINE and cands[baseline][1] == {"visual_stale_rad_s": None, "undo_factor": None}
    assert sorted(o["visual_stale_rad_s"] for n, (_, o) in cands.items() if n != baseline) == [0.25, 0.5]
    assert {o["undo_factor"] for _, o in cands.values()} == {None}  # as before the twentieth stage
    assert make_tracker("set", n_agents=3)._visual.stale_rad_s == 0.5  # shipped since the stage
    assert make_tracker("set", n_agents=3, visual_stale_rad_s=None)._visual.stale_rad_s is None



def test_stage19_candidates_undo_a_recent_exchange_on_less_evidence_against_the_identifier_before_it():
    from set_select_options import STAGE16_BASELINE, stage_candidates

    cands, baseline = stage_candidates(19)
    assert stage_candidates(20) == (cands, baseline)  # the same candidates, judged again after a change of the rule
    assert baseline == STAGE16_BASELINE and cands[baseline][1] == {"undo_factor": None}
    assert sorted(o["undo_factor"] for n, (_, o) in cands.items() if n != baseline) == [0.25, 0.5]
    assert {o["undo_s"] for n, (_, o) in cands.items() if n != baseline} == {30.0}
    assert make_tracker("set", n_agents=3).config.undo_factor == 0.5  # shipped since the twentieth stage
