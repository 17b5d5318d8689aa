"""Report jumps: which agents now report for another robot, and what the identifier must do to their memories."""

import numpy as np

from lookalike.trackers.set.report_jumps import ReportJumps


def step(jumps: ReportJumps, old, new, t_old: float, t_new: float) -> list:
    """One frame at ``t_new`` seconds in which every agent's newest report went from ``old`` to ``new`` (radians)."""
    n = len(old)
    return jumps.find(np.asarray(old, float), np.full(n, t_old), np.asarray(new, float), np.full(n, t_new), t_new)


def test_two_agents_that_swap_headings_exchange_memories_once():
    jumps = ReportJumps(jump=0.5, turn_rate=3.0)
    assert step(jumps, [0.0, 2.0, -2.0], [2.0, 0.0, -2.0], 10.0, 10.1) == [(0, 1)]
    assert step(jumps, [2.0, 0.0, -2.0], [2.0, 0.0, -2.0], 10.1, 10.2) == []  # small turns are no jumps


def test_a_jump_with_no_partner_waits_for_its_mirror_and_is_forgotten_when_none_comes():
    jumps = ReportJumps(jump=0.5, turn_rate=3.0)
    assert step(jumps, [0.0, 2.0], [-2.0, 2.0], 10.0, 10.1) == []  # no agent reported -2 before: it waits
    assert 0 in jumps.pending
    actions = step(jumps, [-2.0, 2.0], [-2.0, 2.0], 10.1, 11.2)
    assert len(actions) == 1 and actions[0].tolist() == [0] and not jumps.pending


def test_mirroring_jumps_are_paired_while_one_waits():
    jumps = ReportJumps(jump=0.5, turn_rate=0.0)
    old = [0.0, 2.0, 0.1]  # two agents reported about 0 before: agent 1's jump to 0 has no single partner
    assert step(jumps, old, [0.0, 0.0, 0.1], 10.0, 10.1) == []
    assert step(jumps, [0.0, 0.0, 0.1], [2.0, 0.0, 0.1], 10.1, 10.4) == [(0, 1)]  # agent 0 now reports 1's old


def test_an_exchange_found_elsewhere_makes_the_agents_jumps_its_second_half():
    jumps = ReportJumps(jump=0.5, turn_rate=3.0)
    jumps.exchanged((0, 1), 10.0)
    assert step(jumps, [0.0, 2.0, -2.0], [2.0, 0.0, -2.0], 10.0, 10.1) == []
