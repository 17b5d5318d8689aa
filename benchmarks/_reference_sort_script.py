"""What the reference SORT's own script does, as one process: load every ``*/det/det.txt`` under a
folder with ``np.loadtxt``, run the reference tracker frame by frame and write MOTChallenge rows per
sequence. It imports matplotlib's pyplot at start-up as the reference script does (with the Agg
backend: there is no display here; scikit-image, which it also imports for its display, is not
installed and is left out).

Usage: ``python benchmarks/_reference_sort_script.py DATA_DIR OUTPUT_DIR`` (used by process_speed.py).
"""

from __future__ import annotations

import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.patches  # noqa: F401  (the reference script's start-up imports)
import matplotlib.pyplot  # noqa: F401
import numpy as np
from sort.sort import Sort


def main(data: Path, output: Path) -> None:
    output.mkdir(parents=True, exist_ok=True)
    for det_file in sorted(data.glob("*/det/det.txt")):
        tracker = Sort(max_age=1, min_hits=3, iou_threshold=0.3)
        table = np.loadtxt(det_file, delimiter=",")
        with open(output / f"{det_file.parents[1].name}.txt", "w") as out:
            for frame in range(1, int(table[:, 0].max()) + 1):
                rows = table[table[:, 0] == frame]
                dets = np.empty((len(rows), 6))
                dets[:, 0:2] = rows[:, 2:4]
                dets[:, 2:4] = rows[:, 2:4] + rows[:, 4:6]
                dets[:, 4] = rows[:, 6]
                dets[:, 5] = np.arange(len(rows))
                for d in tracker.update(dets):
                    out.write(f"{frame:d},{int(d[4]):d},{d[0]:.2f},{d[1]:.2f},{d[2] - d[0]:.2f},{d[3] - d[1]:.2f},"
                              "1,-1,-1,-1\n")


if __name__ == "__main__":
    main(Path(sys.argv[1]), Path(sys.argv[2]))
