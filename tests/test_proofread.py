"""lookalike.proofread: corrections as plain edits and as constraints on a re-solved closed set, undo, replay."""

from __future__ import annotations

import numpy as np
import pytest

from lookalike.proofread import Correction, Session, apply_edit
from lookalike.trackers.offline.closed_set import ChainConstraints, assign_identities


def _row(frame: int, tid: int, x: float, y: float) -> list[float]:
    return [frame, tid, x - 5, y - 5, 10, 10, 1, -1, -1, -1]


def _lanes() -> np.ndarray:
    """Three ids on parallel lanes, frames 1-30 (id 3 only in frames 11-20)."""
    rows = [_row(f, 1, 10 * f, 0) for f in range(1, 31)] + [_row(f, 2, 10 * f, 100) for f in range(1, 31)]
    rows += [_row(f, 3, 10 * f, 200) for f in range(11, 21)]
    return np.array(rows, dtype=float)


def _at(rows: np.ndarray, frame: int, y: float) -> int:
    """Id of the row nearest the lane ``y`` (centre) in ``frame``."""
    r = rows[rows[:, 0] == frame]
    return int(r[np.argmin(np.abs(r[:, 3] + r[:, 5] / 2 - y)), 1])


def test_each_plain_correction_and_undo():
    s = Session(_lanes(), frame_rate=10)
    start = s.rows.copy()
    s.apply(Correction("swap", 1, 2, 16))
    assert _at(s.rows, 15, 0) == 1 and _at(s.rows, 16, 0) == 2 and _at(s.rows, 16, 100) == 1
    s.apply(Correction("split", 1, frame=25))
    new = int(s.rows[:, 1].max())
    assert _at(s.rows, 24, 100) == 1 and _at(s.rows, 25, 100) == new
    s.apply(Correction("merge", 1, new))
    assert _at(s.rows, 25, 100) == 1
    s.apply(Correction("assign", 3, 7, frame=15))
    assert _at(s.rows, 14, 200) == 3 and _at(s.rows, 15, 200) == 7
    s.apply(Correction("delete", 7))
    assert 7 not in s.rows[:, 1] and len(s.corrections) == 5
    for _ in range(5):
        s.undo()
    np.testing.assert_array_equal(s.rows, start)
    with pytest.raises(ValueError, match="no correction"):
        s.undo()


def test_swap_from_k_changes_only_frames_from_k():
    rows = _lanes()
    out = apply_edit(rows, Correction("swap", 1, 2, 12))
    before = rows[rows[:, 0] < 12]
    np.testing.assert_array_equal(out[out[:, 0] < 12], before[np.lexsort((before[:, 1], before[:, 0]))])
    s = Session(rows, frame_rate=10)
    change = s.apply(Correction("swap", 1, 2, 12))
    assert min(change.frames) == 12 and change.ids == (1, 2) and change.rows == 2 * 2 * 19


@pytest.mark.parametrize("bad, match", [
    (Correction("swap", 1, 9, 5), "unknown other id 9"),
    (Correction("delete", 8), "unknown track id 8"),
    (Correction("split", 1, frame=99), "frame 99 is out of range"),
    (Correction("assign", 3, 5, frame=25), "no rows at or after frame 25"),
    (Correction("assign", 3, 1, frame=12), "identity 1 already has a row"),
    (Correction("merge", 1, 2), "both have rows"),
])
def test_bad_corrections_raise_and_change_nothing(bad: Correction, match: str):
    s = Session(_lanes(), frame_rate=10)
    with pytest.raises(ValueError, match=match):
        s.apply(bad)
    np.testing.assert_array_equal(s.rows, Session(_lanes(), frame_rate=10).rows)
    assert not s.corrections


def test_malformed_corrections_raise():
    with pytest.raises(ValueError, match="unknown kind"):
        Correction("rename", 1, 2)
    with pytest.raises(ValueError, match="needs track, other, frame"):
        Correction("swap", 1, 2)
    with pytest.raises(ValueError, match="both 3"):
        Correction("merge", 3, 3)


def _crossing() -> np.ndarray:
    """Solver input: two targets converge (frames 1-20), are lost (21-25), go on straight (26-40, ids 3 and 4), are
    lost again (41-43) and go on (44-60, ids 5 and 6 continuing 3 and 4)."""
    rows = []
    for f in range(1, 61):
        if 21 <= f <= 25 or 41 <= f <= 43:
            continue
        up, down = (1, 2) if f <= 20 else (3, 4) if f <= 40 else (5, 6)
        rows += [_row(f, up, 5 * f, 2.5 * f), _row(f, down, 5 * f, 110 - 2.5 * f)]
    return np.array(rows, dtype=float)


def test_identity_constraint_is_held_and_moves_a_later_link():
    on = _crossing()
    base = assign_identities(on, 2, 10)
    a = _at(base, 10, 25)  # the target on the rising line before the crossing
    rising = _at(base, 30, 75) == a  # where the solver sent it after the gap
    assert _at(base, 50, 125 if rising else -15) == a
    other_piece = (26, 4) if rising else (26, 3)
    pinned = ChainConstraints(identity=(((1, 1), a), (other_piece, a)))
    out = assign_identities(on, 2, 10, constraints=pinned)
    assert _at(out, 10, 25) == a and _at(out, 30, 35 if rising else 75) == a  # the other piece after the gap is a
    assert _at(out, 50, -15 if rising else 125) == a  # and the later link (to 5 or 6), not constrained, went with it
    np.testing.assert_array_equal(assign_identities(on, 2, 10, constraints=ChainConstraints()), base)


def test_session_swap_re_solves_and_undo_restores():
    on = _crossing()
    base = assign_identities(on, 2, 10)
    a, b = _at(base, 10, 25), _at(base, 10, 85)
    s = Session(base, frame_rate=10, n_targets=2, solver_input=on)
    assert s.propagates
    lines = {30: (75, 35), 50: (125, -15)}  # rising and falling line
    after = {f: (_at(base, f, up), _at(base, f, down)) for f, (up, down) in lines.items()}
    change = s.apply(Correction("swap", a, b, 26))
    assert _at(s.rows, 10, 25) == a and _at(s.rows, 10, 85) == b
    for f, (up, down) in after.items():  # both lines changed hands, the later pieces too
        assert (_at(s.rows, f, lines[f][0]), _at(s.rows, f, lines[f][1])) == (down, up)
    assert set(change.ids) == {a, b} and max(change.frames) == 60
    s.undo()
    np.testing.assert_array_equal(s.rows, base[np.lexsort((base[:, 1], base[:, 0]))])


def test_conflicting_constraints_raise():
    on = _crossing()
    with pytest.raises(ValueError, match="overlap"):
        assign_identities(on, 2, 10, constraints=ChainConstraints(identity=(((5, 1), 1), ((5, 2), 1))))
    with pytest.raises(ValueError, match="no input row"):
        assign_identities(on, 2, 10, constraints=ChainConstraints(identity=(((22, 1), 1),)))
    with pytest.raises(ValueError, match="not in 1..2"):
        assign_identities(on, 2, 10, constraints=ChainConstraints(identity=(((5, 1), 3),)))


def _chain_sets(n: int, nxt: dict[int, list[int]], n_chains: int):
    """Every set of at most ``n_chains`` disjoint chains over the links ``nxt`` (tracklet -> later tracklets)."""
    def paths(i: int):
        yield [i]
        for j in nxt.get(i, []):
            for rest in paths(j):
                yield [i, *rest]

    every = [p for i in range(n) for p in paths(i)]

    def pick(start: int, used: frozenset[int], left: int):
        yield []
        for k in range(start, len(every)) if left else ():
            if not used & set(every[k]):
                for more in pick(k + 1, used | set(every[k]), left - 1):
                    yield [every[k], *more]

    return pick(0, frozenset(), n_chains)


@pytest.mark.parametrize("seed", range(12))
def test_marked_chains_are_the_best_chains_that_hold_the_marks(seed: int):
    """solve_chains with marks (one chain holds each mark's ``on`` and none of its ``off``) against every chain set."""
    from lookalike.trackers.offline.closed_set import solve_chains

    rng = np.random.default_rng(seed)
    n = 7
    pairs = [(i, j) for i in range(n) for j in range(i + 1, n) if rng.random() < 0.45]
    src, dst = (np.array(x, int) for x in zip(*pairs))
    cost = rng.uniform(0, 6, len(pairs))
    lengths, start, end = rng.uniform(1, 10, n), rng.uniform(0, 3, n), rng.uniform(0, 3, n)
    on_a, on_b = sorted(rng.choice(n, 2, replace=False).tolist()), [int(rng.integers(n))]
    marks = [(on_a, [t for t in rng.choice(n, 2, replace=False).tolist() if t not in on_a]), (on_b, [])]
    nxt: dict[int, list[int]] = {}
    price = {}
    for s_, d_, c_ in zip(src.tolist(), dst.tolist(), cost.tolist()):
        nxt.setdefault(s_, []).append(d_)
        price[(s_, d_)] = c_

    def value(chains: list[list[int]]) -> float:
        return sum(-(lengths[t] - 2.0) for ch in chains for t in ch) + sum(
            price[p] for ch in chains for p in zip(ch[:-1], ch[1:])) + sum(start[ch[0]] + end[ch[-1]] for ch in chains)

    def holds(chains: list[list[int]]) -> bool:
        return all(any(set(on) <= set(ch) and not set(off) & set(ch) for ch in chains) for on, off in marks)

    best = min((value(c) for c in _chain_sets(n, nxt, 2) if holds(c)), default=None)
    if best is None:
        with pytest.raises(ValueError, match="cannot all hold"):
            solve_chains(lengths, (src, dst, cost), 2, 2.0, 60.0, start, end, marks)
        return
    chains = solve_chains(lengths, (src, dst, cost), 2, 2.0, 60.0, start, end, marks)
    assert holds(chains) and value(chains) == pytest.approx(best)


@pytest.mark.parametrize("propagate", [False, True])
def test_replayed_log_gives_the_same_rows(tmp_path, propagate: bool):
    on = _crossing()
    base = assign_identities(on, 2, 10)
    a, b = _at(base, 10, 25), _at(base, 10, 85)
    kw = {"n_targets": 2, "solver_input": on} if propagate else {}
    s = Session(base, frame_rate=10, **kw)
    s.apply(Correction("swap", a, b, 26))
    s.apply(Correction("split", b, frame=50))
    s.save(tmp_path / "out.txt", tmp_path / "log.jsonl")
    again = Session(base, frame_rate=10, **kw)
    again.replay(tmp_path / "log.jsonl")
    np.testing.assert_array_equal(again.rows, s.rows)
    assert again.corrections == s.corrections
    exported = np.loadtxt(tmp_path / "out.txt", delimiter=",")
    np.testing.assert_allclose(exported[:, :6], s.rows[:, :6], atol=1e-3)


def test_doubtful_ranges_are_sorted_most_doubtful_first():
    s = Session(_crossing(), frame_rate=10)
    d = s.doubtful()
    assert [x.doubt for x in d] == sorted((x.doubt for x in d), reverse=True)
    assert all(x.first <= x.last for x in d)


@pytest.mark.parametrize("kind, refused", [("swap", None), ("split", None), ("delete", None),
                                            ("assign", "overlap"), ("merge", "overlap")])
def test_each_correction_kind_re_solves_and_undoes(kind: str, refused: str | None):
    on = _crossing()
    base = assign_identities(on, 2, 10)
    start = base[np.lexsort((base[:, 1], base[:, 0]))]
    a, b = _at(base, 10, 25), _at(base, 10, 85)
    c = {"swap": Correction("swap", a, b, 30), "assign": Correction("assign", a, b, 30),
         "split": Correction("split", a, frame=30), "merge": Correction("merge", a, b),
         "delete": Correction("delete", a)}[kind]
    s = Session(base, frame_rate=10, n_targets=2, solver_input=on)
    if refused:  # b holds those frames: the closed set refuses, says why and changes nothing
        with pytest.raises(ValueError, match=refused):
            s.apply(c)
        np.testing.assert_array_equal(s.rows, start)
        assert not s.corrections
        return
    change = s.apply(c)
    assert s.corrections == [c]
    if kind == "swap":
        was = _at(base, 35, 87.5)
        assert min(change.frames) >= 30 and _at(s.rows, 35, 87.5) == (b if was == a else a)
    if kind == "delete":
        assert change.rows > 0 and a in change.ids
    s.undo()
    np.testing.assert_array_equal(s.rows, start)


def test_log_lines_round_trip_and_bad_lines_raise():
    c = Correction("swap", 1, 2, 5)
    assert Correction.from_json(c.to_json()) == c
    for bad in ('{"kind": "swap"}', '[1, 2]', '{"kind": "swap", "track": 1, "other": 2, "frame": 5, "x": 1}',
                '{"kind": "delete", "track": [1]}', '{"kind": "delete", "track": 1.5}',
                '{"kind": "delete", "track": true}', '{"kind": "delete", "track": null}',
                '{"kind": "swap", "track": 1, "other": 2, "frame": Infinity}'):
        with pytest.raises(ValueError):
            Correction.from_json(bad)


def test_the_latest_correction_wins_and_drops_the_earlier_conflicting_one(tmp_path):
    on = _crossing()
    base = assign_identities(on, 2, 10)
    start = base[np.lexsort((base[:, 1], base[:, 0]))]
    a, b = _at(base, 10, 25), _at(base, 10, 85)
    s = Session(base, frame_rate=10, n_targets=2, solver_input=on)
    first = Correction("swap", a, b, 30)
    s.apply(first)
    s.apply(Correction("split", a, frame=50))  # pins other rows: kept
    # swapped back from 30: contradicts `first`, which is dropped (the new one is not refused)
    change = s.apply(Correction("swap", b, a, 30))
    assert change.dropped == (first,) and s.dropped == [True, False, False]
    assert f"dropped the earlier conflicting correction {first.to_json()}" in change.describe()
    for f in (10, 35):
        assert [_at(s.rows, f, y) for y in (5 * f / 2, 110 - 5 * f / 2)] == [_at(start, f, y) for y in
                                                                            (5 * f / 2, 110 - 5 * f / 2)]
    s.save(tmp_path / "out.txt", tmp_path / "log.jsonl")
    again = Session(base, frame_rate=10, n_targets=2, solver_input=on)
    again.replay(tmp_path / "log.jsonl")  # the log holds every correction; replay drops the same one
    np.testing.assert_array_equal(again.rows, s.rows)
    assert again.dropped == s.dropped
    s.undo()  # the dropped correction comes back with the undo
    assert s.dropped == [False, False] and s.last_change.rows > 0


def test_a_change_counts_the_rows_it_removes():
    on = _crossing()
    base = assign_identities(on, 2, 10)
    b = _at(base, 10, 85)
    s = Session(base, frame_rate=10, n_targets=2, solver_input=on)
    change = s.apply(Correction("split", b, frame=50))  # both identities are taken from frame 50 on
    assert change.removed == len(base) - len(s.rows) > 0 and f"({change.removed} of them removed)" in change.describe()
    assert s.undo().removed == 0 and len(s.rows) == len(base)
    plain = Session(base, frame_rate=10)
    assert plain.apply(Correction("split", b, frame=50)).removed == 0  # a new id, nothing lost
    held = int((plain.rows[:, 1] == b).sum())
    assert plain.apply(Correction("delete", b)).removed == held > 0
