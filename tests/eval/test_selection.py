"""Leave-one-sequence-out choice: a sequence's own result never decides what it is scored with."""

from __future__ import annotations

import pytest

from lookalike.eval import combine, evaluate_sequence, headline, leave_one_out
from tests.eval.test_metrics_small import A, table

GT = table([(f, 1, *A) for f in range(1, 5)])
PERFECT = evaluate_sequence(GT, table([(f, 10, *A) for f in range(1, 5)]))
HALF = evaluate_sequence(GT, table([(1, 10, *A), (2, 10, *A)]))
EMPTY = evaluate_sequence(GT, table([]))


def test_each_sequence_is_scored_with_the_choice_of_the_others() -> None:
    # candidate 0 is perfect on sequence 0 and empty on 1, candidate 1 the other way round: each
    # sequence gets the candidate that was best on the *other* one, so both are scored empty
    held, chosen = leave_one_out([[PERFECT, EMPTY], [EMPTY, PERFECT]])
    assert chosen == [1, 0]
    assert held["CLR_TP"] == 0 and held["HOTA"] == 0.0
    # a choice that saw its own sequence would have scored perfectly
    assert headline(combine([PERFECT, PERFECT])) > headline(held)


def test_the_criterion_combines_the_other_sequences() -> None:
    # leaving out 2, candidate 0 has {perfect, perfect} and wins; leaving out 0 or 1 it has
    # {perfect, empty}, which still beats {half, half} on HOTA (association)
    held, chosen = leave_one_out([[PERFECT, PERFECT, EMPTY], [HALF, HALF, HALF]])
    assert chosen == [0, 0, 0]
    assert held["MOTA"] == pytest.approx(combine([PERFECT, PERFECT, EMPTY])["MOTA"])
    # the criterion is the caller's: preferring the lower HOTA turns every choice round
    assert leave_one_out([[PERFECT, PERFECT, EMPTY], [HALF, HALF, HALF]], lambda s: -s["HOTA"])[1] == [1, 1, 1]


def test_ties_choose_the_first_candidate_and_bad_shapes_are_refused() -> None:
    assert leave_one_out([[HALF, HALF], [HALF, HALF]])[1] == [0, 0]
    with pytest.raises(ValueError, match="two sequences"):
        leave_one_out([[HALF]])
    with pytest.raises(ValueError, match="every candidate"):
        leave_one_out([[HALF, HALF], [HALF]])
    with pytest.raises(ValueError, match="at least one"):
        leave_one_out([])


def test_missing_scores_are_named() -> None:
    # a dict without the criterion's metrics, or results of different kinds, ended in a KeyError
    with pytest.raises(ValueError, match="scores: lacks 'HOTA'"):
        headline({"IDF1": 1.0, "MOTA": 1.0})
    with pytest.raises(ValueError, match="scores: lacks"):
        leave_one_out([[{}, {}]])
    with pytest.raises(ValueError, match="per_sequence: a result lacks 'Dets'"):
        combine([PERFECT, {}])
