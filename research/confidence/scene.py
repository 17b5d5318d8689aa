"""Two per-result features for the row confidence against the shipped six, leave one dataset out, as
``scene-rule.md`` fixes it (one run; output in ``scene-result.txt``). Run from the repository root::

    OMP_NUM_THREADS=1 .venv/bin/python research/confidence/scene.py | tee research/confidence/scene-result.txt
"""

from __future__ import annotations

import time

import numpy as np
from fit import DATASETS, THRESHOLD, Result, ece, fit, results, stack, switch_share

from lookalike.trackers.offline.confidence import logistic


def scene_features(r: Result) -> np.ndarray:
    """``(k, 2)``: the result's turnover and contact share, the same on every row (scene-rule.md)."""
    frames = np.unique(r.rows[:, 0])
    per_frame = len(r.rows) / max(len(frames), 1)
    turnover = np.log(max(len(np.unique(r.rows[:, 1])), 1) / max(per_frame, 1e-9))
    contact = float(np.mean(r.features[:, 0] < 1.0)) if len(r.rows) else 0.0
    return np.tile([turnover, contact], (len(r.rows), 1))


def main() -> None:
    t0 = time.process_time()
    base = results()
    wide = [Result(r.dataset, r.kind, r.name, r.fps, r.rows, np.column_stack([r.features, scene_features(r)]),
                   r.label, r.switches, r.idp_eval) for r in base]
    print(f"\n{len(base)} results; baseline: 6 row features; variant: + turnover, contact_share\n")
    print("left out     | rows    | ECE baseline | ECE variant | switches in a range (baseline / variant)")
    verdict = []
    for d in DATASETS:
        line = []
        for rs in (base, wide):
            x, y, w = stack([r for r in rs if r.dataset != d])
            coef = fit(x, y, w)
            test = [r for r in rs if r.dataset == d]
            probs = [logistic(r.features, coef) for r in test]
            keep = np.concatenate([r.label >= 0 for r in test])
            p = np.concatenate(probs)[keep]
            yt = np.concatenate([r.label for r in test])[keep].astype(float)
            inside, total, _ = switch_share(test, probs, THRESHOLD)
            line.append((ece(p, yt)[0], inside, total, len(yt), coef))
        (e0, i0, t0_, n, _), (e1, i1, _, _, c1) = line
        verdict.append(e1 - e0)
        print(f"{d:12s} | {n:7d} | {e0:.3f}        | {e1:.3f}       | {i0}/{t0_} / {i1}/{t0_}")
        print(f"{'':12s}   variant's coefficients without it: " + ", ".join(f"{c:.4f}" for c in c1))
    lower = sum(v < 0 for v in verdict)
    worse = [v for v in verdict if v > 0.01]
    kept = lower >= 3 and not worse
    print(f"\nECE lower on {lower} of 4, higher by more than 0.01 on {len(worse)}: "
          f"{'kept' if kept else 'not kept'} (scene-rule.md)")
    print(f"({time.process_time() - t0:.0f} s CPU)")


if __name__ == "__main__":
    main()
