"""Identities of look-alike animals on video: the documented command ``lookalike track --video V --detector blob
-t boxtrack --targets N`` (by default the offline closed set with each animal's look learned from the video) and with
``--online`` (the frame-by-frame closed set) on rendered arenas and on test_A against idtracker.ai's trajectories.

Scoring as the release checks do it: a result box stands for its centre; it matches a reference animal in a frame when
within ``RADIUS_PX``; one global one-to-one mapping of result ids to reference ids maximises the matched frames
(IDTP); IDF1 = 2 IDTP / (reference points + result boxes); "all right" counts the frames where every one of the N
animals has its mapped id within reach. CPU time is the command's, learning included, on a fresh detection cache.
A row is right when its mapped animal is within reach in its frame; the row confidence (column 7) is scored by its
expected calibration error over 10 bins.

Arenas: ``lookalike simulate --arena`` defaults, seeds ``--seeds`` (10000-10019 by default: never used for any choice;
research/appearance/rule17.md). test_A: ``../shared/data/zebrafish/test_A.avi`` against ``idtracker_test_A.csv``.

    python benchmarks/video_identities.py [--seeds 10000-10019] [--no-test-a] [--no-arenas] [--modes default online]
"""

from __future__ import annotations

import argparse
import os
import resource
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np
from scipy.optimize import linear_sum_assignment

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _common import SHARED_DATA, report_target  # noqa: E402

RADIUS_PX = 15.0
IDTRACKER_CPU_S = 1600.0  # idtracker.ai 6.0.14 on test_A, this machine's CPU, contrastive step off (issue 50)
MODES = {"default": [], "online": ["--online"]}


def parse_seeds(text: str) -> list[int]:
    lo, _, hi = text.partition("-")
    return list(range(int(lo), int(hi or lo) + 1))


def identity_scores(result: np.ndarray, reference: np.ndarray, n: int) -> dict[str, float]:
    """IDF1, matched frames and frames with all ``n`` right of result rows ``(frame, id, x, y, w, h)`` against
    reference rows ``(frame, id, x, y)`` (1-based frames, px)."""
    centres = result[:, 2:4] + result[:, 4:6] / 2
    res_ids, res_idx = np.unique(result[:, 1].astype(int), return_inverse=True)
    ref_ids, ref_idx = np.unique(reference[:, 1].astype(int), return_inverse=True)
    near = np.zeros((len(res_ids), len(ref_ids)))
    hits: dict[tuple[int, int], set[int]] = {}
    by_frame: dict[int, list[int]] = {}
    for k, f in enumerate(result[:, 0].astype(int)):
        by_frame.setdefault(f, []).append(k)
    for g, (f, x, y) in enumerate(zip(reference[:, 0].astype(int), reference[:, 2], reference[:, 3])):
        rows = np.array(by_frame.get(f, []), dtype=int)
        if not len(rows):
            continue
        close = rows[np.hypot(centres[rows, 0] - x, centres[rows, 1] - y) <= RADIUS_PX]
        for r in close:
            near[res_idx[r], ref_idx[g]] += 1
            hits.setdefault((int(res_idx[r]), int(ref_idx[g])), set()).add(f)
    a, b = linear_sum_assignment(-near)
    idtp = float(near[a, b].sum())
    mapped = dict(zip(a.tolist(), b.tolist()))
    right = np.array([f in hits.get((int(i), mapped.get(int(i), -1)), ()) for i, f in
                      zip(res_idx, result[:, 0].astype(int))], dtype=bool)  # on its mapped animal, within reach
    frames = np.unique(reference[:, 0].astype(int))
    full = [f for f in frames if np.sum(reference[:, 0] == f) == n]
    all_right = sum(all(f in hits.get((int(i), int(j)), ()) for i, j in zip(a, b)) and len(b) == n for f in full)
    return {"IDF1": 2 * idtp / (len(reference) + len(result)), "all_right": all_right, "full_frames": len(full),
            "ece": calibration_error(result[:, 6], right) if result.shape[1] > 6 else float("nan"),
            "switch_events": _switches(result, reference, dict(zip(b.tolist(), a.tolist())), ref_idx, res_ids)}


def calibration_error(confidence: np.ndarray, right: np.ndarray, bins: int = 10) -> float:
    """Expected calibration error of per-row confidences (column 7 of a result) against whether each row is right:
    ``bins`` equal-width bins on [0, 1], rows-weighted mean |mean confidence - share right|."""
    b = np.minimum((np.asarray(confidence) * bins).astype(int), bins - 1)
    gap = np.abs(np.bincount(b, confidence, bins) - np.bincount(b, right.astype(float), bins))
    return float(gap.sum() / max(len(b), 1)) if len(b) else float("nan")


def _switches(result: np.ndarray, reference: np.ndarray, mapping: dict[int, int], ref_idx: np.ndarray,
              res_ids: np.ndarray) -> int:
    """Changes of the result id nearest to each reference animal (within reach) from one matched frame to the next."""
    centres = result[:, 2:4] + result[:, 4:6] / 2
    count = 0
    for g in np.unique(ref_idx):
        sel = reference[ref_idx == g]
        last = None
        for f, x, y in zip(sel[:, 0], sel[:, 2], sel[:, 3]):
            rows = np.flatnonzero(result[:, 0] == f)
            if not len(rows):
                continue
            d = np.hypot(centres[rows, 0] - x, centres[rows, 1] - y)
            if d.min() > RADIUS_PX:
                continue
            now = int(result[rows[np.argmin(d)], 1])
            count += last is not None and now != last
            last = now
    return count


def run_track(video: Path, n: int, extra: list[str], out: Path, cache: Path) -> tuple[np.ndarray, float]:
    """Result rows and CPU seconds of the documented command on ``video``."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    env = {**os.environ, "LOOKALIKE_CACHE": str(cache)}
    cmd = [sys.executable, "-m", "lookalike", "track", "--video", str(video), "--detector", "blob", "-t", "boxtrack",
           "--targets", str(n), *extra, "-o", str(out)]
    subprocess.run(cmd, check=True, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = after.ru_utime - before.ru_utime + after.ru_stime - before.ru_stime
    return np.loadtxt(out, delimiter=",", ndmin=2), cpu


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", default="10000-10019", help="arena seeds, LO-HI")
    parser.add_argument("--modes", nargs="*", default=list(MODES), choices=list(MODES))
    parser.add_argument("--no-test-a", action="store_true")
    parser.add_argument("--no-arenas", action="store_true")
    args = parser.parse_args()
    work = Path(tempfile.mkdtemp(prefix="video-ids-"))
    if not args.no_arenas:
        from lookalike.io.arena_files import write_arena

        scores: dict[str, list[float]] = {m: [] for m in args.modes}
        for seed in parse_seeds(args.seeds):
            files = write_arena(work / f"arena{seed}", seed=seed)
            truth = np.loadtxt(files.gt, delimiter=",", ndmin=2)
            reference = np.column_stack([truth[:, :2], truth[:, 2:4] + truth[:, 4:6] / 2])
            n = len(np.unique(truth[:, 1]))
            for mode in args.modes:
                rows, cpu = run_track(files.video, n, MODES[mode], work / f"a{seed}-{mode}.txt", work / "cache")
                s = identity_scores(rows, reference, n)
                scores[mode].append(s["IDF1"])
                print(f"arena seed {seed} {mode:8s} IDF1 {s['IDF1']:.4f}  all {n} right {s['all_right']}/"
                      f"{s['full_frames']}  switches {s['switch_events']}  confidence ECE {s['ece']:.3f}  "
                      f"CPU {cpu:.1f} s", flush=True)
        for mode in args.modes:
            mean = float(np.mean(scores[mode]))
            print(f"arenas {args.seeds} {mode}: mean IDF1 {mean:.4f}, min {min(scores[mode]):.4f}")
            if mode == "default":
                report_target("rendered arenas, --targets N: mean IDF1", mean, 0.99)
    ref_path = SHARED_DATA / "zebrafish" / "idtracker_test_A.csv"
    if not args.no_test_a and ref_path.is_file():
        ref = np.loadtxt(ref_path, delimiter=",", skiprows=1, ndmin=2)
        ref[:, 0] += 1  # idtracker.ai's frames are 0-based
        for mode in args.modes:
            rows, cpu = run_track(SHARED_DATA / "zebrafish" / "test_A.avi", 8, MODES[mode], work / f"zf-{mode}.txt",
                                  work / f"cache-zf-{mode}")
            s = identity_scores(rows, ref, 8)
            print(f"test_A {mode:8s} IDF1 {s['IDF1']:.4f}  all 8 right {s['all_right']}/{s['full_frames']}  "
                  f"switches {s['switch_events']}  confidence ECE {s['ece']:.3f}  CPU {cpu:.1f} s (fresh cache)",
                  flush=True)
            if mode == "default":
                report_target("test_A --targets 8: row confidence, expected calibration error", s["ece"], 0.05,
                              higher_is_better=False)
                report_target("test_A --targets 8: IDF1 vs idtracker.ai", s["IDF1"], 0.99)
                report_target("test_A --targets 8: share of frames with all 8 right", s["all_right"] /
                              max(s["full_frames"], 1), 0.95)
                report_target("test_A --targets 8: CPU seconds, learning included", cpu, IDTRACKER_CPU_S / 10,
                              higher_is_better=False, unit=" s")
    elif not args.no_test_a:
        print(f"test_A: {ref_path} not found; skipped")


if __name__ == "__main__":
    main()
