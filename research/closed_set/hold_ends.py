"""Holding each identity at the sequence's ends, by leave-one-dataset-out, as ``hold-ends-rule.md`` fixes it (one
run; output in ``hold-ends-result.txt``). Run from the repository root with ../shared/data beside it::

    OMP_NUM_THREADS=1 .venv/bin/python research/closed_set/hold_ends.py | tee research/closed_set/hold-ends-result.txt

Not shipped: the switch left the package after this run. To rerun it, check out the commit that had it
(`git worktree add /tmp/hold 72f4276`, then `PYTHONPATH=/tmp/hold/src`).
"""

from __future__ import annotations

import time

import numpy as np
from lodo import cases, value

from lookalike.trackers.offline.closed_set import ClosedSetConfig, assign_identities

CANDIDATES = (False, True)  # hold_ends, with the shipped constants (tracklet_cost 1, edge_cost 10, smooth_s 1)


def main() -> None:
    t0 = time.process_time()
    data = cases()
    groups = sorted({c.group for c in data})
    print(f"{len(data)} sequences ({', '.join(f'{g}: {sum(c.group == g for c in data)}' for g in groups)}), "
          f"hold_ends off / on", flush=True)
    scores = {cand: {c.name: c.score(assign_identities(c.first_pass, c.n, c.fps, ClosedSetConfig(hold_ends=cand)))
                     for c in data} for cand in CANDIDATES}
    table = {cand: {name: value(s) for name, s in by_name.items()} for cand, by_name in scores.items()}

    def group_score(cand: bool, g: str) -> float:
        return float(np.mean([table[cand][c.name] for c in data if c.group == g]))

    for cand in CANDIDATES:
        print(f"  hold_ends={cand}: " + "  ".join(f"{g} {group_score(cand, g):.2f}" for g in groups))
    for c in data:
        print(f"    {c.name}: off {table[False][c.name]:.2f}  on {table[True][c.name]:.2f}")

    def choose(train: list[str]) -> bool:
        return max(CANDIDATES, key=lambda cand: (round(np.mean([group_score(cand, g) for g in train]), 9), not cand))

    print("\nleft out | chosen on the others | IDF1+HOTA left out: chosen / off")
    folds_ok = []
    for g in groups:
        cand = choose([h for h in groups if h != g])
        folds_ok.append(group_score(cand, g) >= group_score(False, g))
        print(f"{g:8s} | hold_ends={cand} | {group_score(cand, g):.2f} / {group_score(False, g):.2f}")
        if g == "pigs":
            for c in data:
                if c.group == "pigs":
                    s = scores[cand][c.name]
                    print(f"         {c.name}: IDF1 {100 * s['IDF1']:.2f} HOTA {100 * s['HOTA']:.2f}")
    on_all = choose(groups)
    ship = on_all and all(folds_ok)
    print(f"\nchosen on all three groups: hold_ends={on_all}; every fold at least off: {all(folds_ok)}; "
          f"ship: hold_ends={ship}  ({time.process_time() - t0:.0f} s CPU)")


if __name__ == "__main__":
    main()
