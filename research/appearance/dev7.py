"""Development runs of research/appearance/rule7.md (arena seeds 0-9 and 4000-4019, the 14 HexBug clips): the
offline closed set with the look's log-likelihood ratios weighed 1, 1.5, 2 and 3 against motion. Not a scoring run.
Usage: dev7.py [arenas,hexbug]"""
import sys
import tempfile
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "benchmarks"))
from _common import SHARED_DATA  # noqa: E402
from video_identities import identity_scores  # noqa: E402

import lookalike.trackers.offline.appearance as appearance  # noqa: E402
from lookalike.bench.datasets import read_hexbug_points  # noqa: E402
from lookalike.eval import evaluate_points  # noqa: E402
from lookalike.io.arena_files import write_arena  # noqa: E402
from lookalike.io.video_frames import source_frames  # noqa: E402
from lookalike.pipeline.blob_detections import auto_blob_config, cached_blob_detections  # noqa: E402
from lookalike.trackers.offline.closed_set import track_closed_set  # noqa: E402
from lookalike.vision.blob_auto import BOX_TRACKER_PARAMS  # noqa: E402

work = Path(tempfile.mkdtemp(prefix="appearance-dev7-"))
WEIGHTS = (1.0, 1.5, 2.0, 3.0)
MODES = tuple(f"w={w:g}" for w in WEIGHTS)


def run(video, n):
    config, _ = auto_blob_config(video, [], n)
    found = cached_blob_detections(video, config, cache=work / "cache")
    fps = source_frames(video)[2] or 25.0
    out = []
    for w in WEIGHTS:
        appearance.LOOK_WEIGHT = w
        try:
            out.append(track_closed_set(found.rows, n, fps, n_frames=found.frames, online=dict(BOX_TRACKER_PARAMS),
                                        shapes=found.shapes, parts=found.parts))
        finally:
            appearance.LOOK_WEIGHT = 1.0
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
    for j in range(1, len(MODES)):
        d = t[:, j] - t[:, 0]
        print(f"{name}: {MODES[0]} {t[:, 0].mean():.4f} {MODES[j]} {t[:, j].mean():.4f} diff {d.mean():+.4f} "
              f"(se {d.std(ddof=1) / np.sqrt(len(d)):.4f}; up {(d > 0).sum()}, down {(d < 0).sum()})")


if __name__ == "__main__":
    which = sys.argv[1].split(",") if len(sys.argv) > 1 else ["arenas", "hexbug"]
    if "arenas" in which:
        summary("arenas 0-9, 4000-4019", arenas([*range(10), *range(4000, 4020)]))
    if "hexbug" in which:
        summary("hexbug", hexbug())
