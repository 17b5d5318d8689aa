"""SORT with many boxes: lookalike's ``sort`` beside the reference SORT at 100 and 1,000 detections
a frame, measured in one run.

Run with ``make bench`` or ``python benchmarks/track_scaling.py [--rounds 3]``. The scenes are
simulated (``lookalike.sim.simulate_boxes``: targets on a field whose area grows with their number,
so the density stays that of a busy street; 10% missed, 5% clutter); detections are made
beforehand and each round runs both trackers in turn (median over rounds). Prints frames/s of
CPU time (``time.process_time``), the ratio and whether the outputs agree (same boxes, ids a
consistent renaming).
"""

from __future__ import annotations

import os

os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import argparse
import statistics
import sys
import time

import numpy as np
from _common import report_target
from _peers import lookalike_runner, reference_sort
from track_speed import same_as_reference

from lookalike.sim import BoxSceneConfig, simulate_boxes

SIZES = {100: 40, 1000: 5}  # detections a frame -> frames simulated


def scene(n_targets: int, frames: int, seed: int = 0) -> list[tuple[np.ndarray, np.ndarray]]:
    """Per-frame ``(xywh, score)`` of a simulated crowd of ``n_targets`` boxes."""
    side = int(64 * np.sqrt(n_targets))
    config = BoxSceneConfig(seed=seed, frames=frames, n_targets=n_targets, image_size=(side * 4 // 3, side),
                            false_positives_per_frame=0.05 * n_targets, speed_px=6.0)
    return [(f.detections.xywh, f.detections.score) for f in simulate_boxes(config).frames]


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rounds", type=int, default=3)
    args = parser.parse_args()
    reference = reference_sort()
    if reference is None:
        print("reference SORT not installed: nothing to compare (make bench installs it)")
        return 0
    ours = lookalike_runner("sort")
    for n, frames in SIZES.items():
        seqs = [scene(n, frames)]
        per_frame = np.mean([len(x) for x, _ in seqs[0]])
        times: dict[str, list[float]] = {"sort": [], "reference": []}
        outputs: dict[str, list] = {}
        for _ in range(args.rounds):
            for name, run in (("sort", ours), ("reference", reference)):
                t0 = time.process_time()
                outputs[name] = run(seqs)  # type: ignore[assignment]
                times[name].append(time.process_time() - t0)
        fps = {name: frames / statistics.median(t) for name, t in times.items()}
        same = same_as_reference(outputs["sort"], outputs["reference"])
        print(f"{per_frame:,.0f} detections a frame, {frames} frames: sort {fps['sort']:,.1f} frames/s, "
              f"reference {fps['reference']:,.1f} frames/s; same output (ids renamed): {same}")
        report_target(f"sort vs reference SORT at {n} detections a frame (x)", fps["sort"] / fps["reference"], 5.0)
    return 0


if __name__ == "__main__":
    sys.exit(main())
