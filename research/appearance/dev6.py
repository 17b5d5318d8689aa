"""Development runs of research/appearance/rule6.md (arena seeds 0-9 and 4000-4019, the 14 HexBug clips): round 5
(profiles as the area turns them) against round 6 (turned head first by the motion). Not a scoring run.
Usage: dev6.py [arenas,hexbug]. Round 6 was not kept: this runs only on a tree with its code (`head_first` in
trackers/offline/appearance.py, called first in `assign_identities`, and the profiles' direction as two more columns
of `blob_shapes`), as described in rule6.md."""
import sys
import tempfile
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "benchmarks"))
from _common import SHARED_DATA  # noqa: E402
from video_identities import identity_scores  # noqa: E402

import lookalike.trackers.offline.closed_set as closed_set  # noqa: E402
from lookalike.bench.datasets import read_hexbug_points  # noqa: E402
from lookalike.eval import evaluate_points  # noqa: E402
from lookalike.io.arena_files import write_arena  # noqa: E402
from lookalike.io.video_frames import source_frames  # noqa: E402
from lookalike.pipeline.blob_detections import auto_blob_config, cached_blob_detections  # noqa: E402
from lookalike.trackers.offline.appearance import head_first  # noqa: E402
from lookalike.vision.blob_auto import BOX_TRACKER_PARAMS  # noqa: E402
from lookalike.vision.blob_shape import LOOK_SIZE  # noqa: E402

work = Path(tempfile.mkdtemp(prefix="appearance-dev6-"))
MODES = ("round5", "round6")


def run(video, n):
    config, _ = auto_blob_config(video, [], n)
    found = cached_blob_detections(video, config, cache=work / "cache")
    fps = source_frames(video)[2] or 25.0
    out = []
    for mode in MODES:
        closed_set.head_first = head_first if mode == "round6" else (lambda rows, shapes: shapes[:, :LOOK_SIZE])
        try:
            out.append(closed_set.track_closed_set(found.rows, n, fps, n_frames=found.frames,
                                                   online=dict(BOX_TRACKER_PARAMS), shapes=found.shapes,
                                                   parts=found.parts))
        finally:
            closed_set.head_first = head_first
    return out


def arenas(seeds):
    table = []
    for seed in seeds:
        files = write_arena(work / f"arena{seed}", seed=seed)
        truth = np.loadtxt(files.gt, delimiter=",", ndmin=2)
        ref = np.column_stack([truth[:, :2], truth[:, 2:4] + truth[:, 4:6] / 2])
        n = len(np.unique(truth[:, 1]))
        row = [identity_scores(r, ref, n)["IDF1"] for r in run(files.video, n)]
        table.append(row)
        print(f"arena {seed}: " + " ".join(f"{m} {v:.4f}" for m, v in zip(MODES, row)), flush=True)
    return np.array(table)


def hexbug():
    table = []
    for video in sorted((SHARED_DATA / "hexbug").glob("*.mp4")):
        img = next(iter(source_frames(video)[0]))
        gt = read_hexbug_points(video.with_suffix(".csv"), (img.shape[1], img.shape[0]))
        n = len(np.unique(gt[1]))
        row = []
        for rows in run(video, n):
            c = rows[:, 2:4] + rows[:, 4:6] / 2
            m = evaluate_points(gt[0], gt[1], gt[2], rows[:, 0].astype(int), rows[:, 1].astype(int), c, radius=120.0,
                                num_frames=101)
            row.append(m["IDF1"])
        table.append(row)
        print(f"hexbug {video.stem} (N={n}): " + " ".join(f"{m} {v:.4f}" for m, v in zip(MODES, row)), flush=True)
    return np.array(table)


def summary(name, t):
    d = t[:, 1] - t[:, 0]
    print(f"{name}: round5 {t[:, 0].mean():.4f} round6 {t[:, 1].mean():.4f} diff {d.mean():+.4f} "
          f"(se {d.std(ddof=1) / np.sqrt(len(d)):.4f}; up {(d > 0).sum()}, down {(d < 0).sum()})")


if __name__ == "__main__":
    which = sys.argv[1].split(",") if len(sys.argv) > 1 else ["arenas", "hexbug"]
    if "arenas" in which:
        summary("arenas 0-9, 4000-4019", arenas([*range(10), *range(4000, 4020)]))
    if "hexbug" in which:
        summary("hexbug", hexbug())
