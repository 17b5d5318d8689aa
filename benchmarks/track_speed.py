"""Tracker speed on the MOT15 detections: lookalike's ``sort`` and ``boxtrack`` beside the reference
SORT and the ``trackers`` package's SORT and ByteTrack, measured in one run.

Run with ``make bench`` (installs the peers into .venv-bench) or directly: ``python
benchmarks/track_speed.py [--data ../shared/data/mot15] [--rounds 5]``. Detections are loaded
beforehand; each round runs every tracker once over all sequences in turn (interleaved, so a busy
moment hurts all alike) and the median over rounds is reported, in frames/s of CPU time
(``time.process_time``: on a shared machine the time spent waiting for a core is not counted; on an
idle one it equals wall time), with each lookalike tracker's ratio to every peer. Before the rounds each
tracker runs once on the first 50 frames of the first sequence: what a process pays once (lazy imports such
as scipy's solver, and for ``boxtrack`` importing numba and loading its cached compiled kernels, which a short run
of the ``lookalike`` program skips) is printed apart and not counted in the rounds. ``sort``'s output
is compared with the reference's, frame by frame (same boxes; ids a consistent renaming, since the
reference numbers new tracks of one frame in the order its solver leaves them and lookalike in
detection order).
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
from _common import SHARED_DATA, report_target
from _peers import load_mot_sequences, lookalike_runner, reference_rows, reference_sort, trackers_runner

TARGETS = [  # (lookalike tracker, peer, minimum ratio)
    ("sort", "reference SORT", 4.0),
    ("sort", "trackers SORT", 2.0),
    ("boxtrack", "reference SORT", 2.0),
    ("boxtrack", "trackers ByteTrack", 1.5),
]


def same_as_reference(ours: list, reference: list) -> bool:
    """Whether lookalike's ``sort`` reported the same boxes (to 1e-6 pixels) in every frame, with ids
    that are a consistent renaming of the reference's (new tracks may be numbered in another order)."""
    for seq_ours, seq_ref in zip(ours, reference):
        renaming: dict[int, int] = {}
        for tracks, ref in zip(seq_ours, reference_rows(seq_ref)):
            if len(tracks) != len(ref):
                return False
            for i, box in zip(tracks.id.tolist(), tracks.xywh):
                near = [rid for rid, rbox in ref if np.allclose(box, rbox, rtol=0, atol=1e-6)]
                if len(near) != 1 or renaming.setdefault(i, near[0]) != near[0]:
                    return False
        if len(set(renaming.values())) != len(renaming):
            return False
    return True


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--data", default=str(SHARED_DATA / "mot15"))
    parser.add_argument("--rounds", type=int, default=5)
    args = parser.parse_args()
    try:
        seqs, rates = load_mot_sequences(args.data)
    except FileNotFoundError:
        print(f"MOT15 data not found at {args.data}: nothing to measure")
        return 0
    runners = {"sort": lookalike_runner("sort", rates), "boxtrack": lookalike_runner("boxtrack", rates)}
    for name, runner in [("reference SORT", reference_sort()), ("trackers SORT", trackers_runner("sort", rates)),
                         ("trackers ByteTrack", trackers_runner("bytetrack", rates))]:
        if runner is None:
            print(f"{name}: not installed, skipped (make bench installs it)")
        else:
            runners[name] = runner
    n_frames = sum(len(s) for s in seqs)
    print(f"{len(seqs)} sequences, {n_frames} frames, median of {args.rounds} interleaved rounds, "
          "tracker CPU time only (input objects built per frame)")
    from lookalike.trackers.boxtrack import BoxTrack
    from lookalike.trackers.kernels import boxtrack as boxtrack_kernels

    first = []
    for name, run in runners.items():
        t0 = time.process_time()
        if name == "boxtrack":  # a long run's steady state: the kernels loaded now, not once the numpy path paid
            boxtrack_kernels.compiled()
        run([seqs[0][:50]])
        first.append(f"{name} {time.process_time() - t0:.2f} s")
    compiled = BoxTrack().compiled
    print("one-off start-up, CPU of a first run on 50 frames (not in the rounds): " + ", ".join(first)
          + f"; boxtrack's compiled kernels {'on' if compiled else 'off'} (LOOKALIKE_BOXTRACK_NUMBA)")
    times: dict[str, list[float]] = {name: [] for name in runners}
    outputs: dict[str, object] = {}
    for _ in range(args.rounds):
        for name, run in runners.items():
            t0 = time.process_time()
            outputs[name] = run(seqs)
            times[name].append(time.process_time() - t0)
    fps = {name: n_frames / statistics.median(t) for name, t in times.items()}
    for name, value in fps.items():
        print(f"{name:22s} {value:10,.0f} frames/s")
    if "reference SORT" in outputs:
        same = same_as_reference(outputs["sort"], outputs["reference SORT"])  # type: ignore[arg-type]
        print(f"sort's output equals the reference SORT's on all {len(seqs)} sequences (ids renamed): {same}")
    for ours, peer, target in TARGETS:
        if peer in fps:
            report_target(f"{ours} vs {peer} (MOT15, x)", fps[ours] / fps[peer], target)
    return 0


if __name__ == "__main__":
    sys.exit(main())
