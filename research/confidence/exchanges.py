"""Where fresh arenas lost an exchange that lasts (seeds 10008, 9014, 8018: scored before as confirmations, looked at
here for diagnosis only): per identity, its wrong rows and the mean look margin of its right and of its wrong rows.
Run from research/confidence with ``PYTHONPATH=.``; output in ``exchanges.txt``."""

from __future__ import annotations

import tempfile
from pathlib import Path

import numpy as np
from look import arenas


def mean_margin(m: np.ndarray, sel: np.ndarray) -> float:
    judged = sel & ~np.isnan(m)
    return float(m[judged].mean()) if judged.any() else float("nan")


def main() -> None:
    work = Path(tempfile.mkdtemp(prefix="exchanges-"))
    for seed in (10008, 9014, 8018):
        r, _, m = arenas([seed], work)[0]
        wrong, ids = r.label == 0, r.rows[:, 1].astype(int)
        print(f"{seed} wrong {wrong.sum()}: margin < 0 {(wrong & (m < 0)).sum()}, > 0 {(wrong & (m > 0)).sum()}, "
              f"not judged {(wrong & np.isnan(m)).sum()}")
        for i in np.unique(ids):
            s = ids == i
            print(f"  id {i} rows {s.sum()} wrong {(wrong & s).sum()} mean margin: right rows "
                  f"{mean_margin(m, s & (r.label == 1)):.2f}, wrong rows {mean_margin(m, s & wrong):.2f}")


if __name__ == "__main__":
    main()
