"""How well each appearance feature set tells look-alike divers apart, before any tracker.

Run: ``.venv/bin/python benchmarks/diver_features_auc.py [--every 10]``. On the validation
scenarios (the test team, seeds 901–904; never the test scenarios) every ``every``-th frame's
ground-truth boxes with visibility >= 0.5 are described by each feature set; per scenario, all
pairs of crops are scored by cosine similarity and the ROC AUC of same- vs different-diver pairs
is printed (1 = perfectly separated, 0.5 = chance), with the median same- and different-diver
cosine distances.
"""

from __future__ import annotations

import os

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import argparse

import numpy as np


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--every", type=int, default=10)
    parser.add_argument("--features", nargs="+", default=["handcrafted", "learned"])
    args = parser.parse_args()

    from lookalike.learn.appearance_train import verification_auc
    from lookalike.sim.divers import VALIDATION_SCENARIOS, simulate_divers
    from lookalike.sim.divers_run import diver_extractor

    extractors = {name: diver_extractor(name) for name in args.features}
    print(f"{'scenario':24s} " + " ".join(f"{n:>24s}" for n in extractors))
    pooled: dict[str, list[float]] = {n: [] for n in extractors}
    for sc in VALIDATION_SCENARIOS:
        scene = simulate_divers(sc)
        feats: dict[str, list[np.ndarray]] = {n: [] for n in extractors}
        labels = []
        for k in range(0, sc.frames, args.every):
            rows = scene.gt[(scene.gt[:, 0] == k + 1) & (scene.gt[:, 8] >= 0.5)]
            if len(rows):
                image = scene.image(k)
                for n, ex in extractors.items():
                    feats[n].append(ex(image, rows[:, 2:6]))
                labels.append(rows[:, 1])
        lab = np.concatenate(labels)
        cells = []
        for n in extractors:
            f = np.vstack(feats[n])
            auc = verification_auc(f, lab)
            pooled[n].append(auc)
            d = 1 - f @ f.T
            iu = np.triu_indices(len(f), 1)
            same = (lab[:, None] == lab[None, :])[iu]
            cells.append(f"AUC {auc:.3f} d {np.median(d[iu][same]):.3f}/{np.median(d[iu][~same]):.3f}")
        print(f"{sc.name:24s} " + " ".join(f"{c:>24s}" for c in cells))
    print(f"{'mean AUC':24s} " + " ".join(f"{np.mean(v):>24.3f}" for v in pooled.values()))


if __name__ == "__main__":
    main()
