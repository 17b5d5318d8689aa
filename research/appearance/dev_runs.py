"""Development runs of research/appearance/rule.md (arena seeds 0-9, HexBug): online closed set (the CLI), offline
closed set without and with the learned look (library, the CLI's parameters). Not a confirmation run."""
import sys
import tempfile
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "benchmarks"))
from _common import SHARED_DATA  # noqa: E402
from video_identities import identity_scores, run_track  # noqa: E402

from lookalike.bench.datasets import read_hexbug_points  # noqa: E402
from lookalike.eval import evaluate_points  # noqa: E402
from lookalike.io.arena_files import write_arena  # noqa: E402
from lookalike.io.video_frames import source_frames  # noqa: E402
from lookalike.pipeline.blob_detections import auto_blob_config, cached_blob_detections  # noqa: E402
from lookalike.trackers.offline.closed_set import track_closed_set  # noqa: E402
from lookalike.vision.blob_auto import BOX_TRACKER_PARAMS  # noqa: E402

work = Path(tempfile.mkdtemp(prefix="appearance-dev-"))


def offline(video: Path, n: int):
    config, _ = auto_blob_config(video, [], n)
    found = cached_blob_detections(video, config)
    fps = source_frames(video)[2] or 25.0
    out = []
    for use in (False, True):
        out.append(track_closed_set(found.rows, n, fps, n_frames=found.frames, online=dict(BOX_TRACKER_PARAMS),
                                    shapes=found.shapes if use else None))
    return out


def arenas(seeds):
    table = []
    for seed in seeds:
        files = write_arena(work / f"arena{seed}", seed=seed)
        truth = np.loadtxt(files.gt, delimiter=",", ndmin=2)
        ref = np.column_stack([truth[:, :2], truth[:, 2:4] + truth[:, 4:6] / 2])
        n = len(np.unique(truth[:, 1]))
        online, _ = run_track(files.video, n, [], work / f"on{seed}.txt", work / "cache")
        plain, look = offline(files.video, n)
        row = [identity_scores(r, ref, n)["IDF1"] for r in (online, plain, look)]
        table.append(row)
        print(f"arena {seed}: online {row[0]:.4f} offline {row[1]:.4f} offline+look {row[2]:.4f}", flush=True)
    return np.array(table)


def hexbug():
    table = []
    for video in sorted((SHARED_DATA / "hexbug").glob("*.mp4")):
        frames, _, _ = source_frames(video)
        img = next(iter(frames))
        gt = read_hexbug_points(video.with_suffix(".csv"), (img.shape[1], img.shape[0]))
        n = len(np.unique(gt[1]))
        online, _ = run_track(video, n, [], work / f"{video.stem}.txt", work / "cache")
        row = []
        for rows in (online, *offline(video, n)):
            c = rows[:, 2:4] + rows[:, 4:6] / 2
            m = evaluate_points(gt[0], gt[1], gt[2], rows[:, 0].astype(int), rows[:, 1].astype(int), c, radius=120.0,
                                num_frames=101)
            row.append(m["IDF1"])
        table.append(row)
        print(f"hexbug {video.stem} (N={n}): online {row[0]:.4f} offline {row[1]:.4f} offline+look {row[2]:.4f}",
              flush=True)
    return np.array(table)


def summary(name, t):
    d1, d2 = t[:, 2] - t[:, 1], t[:, 2] - t[:, 0]
    se = lambda d: d.std(ddof=1) / np.sqrt(len(d))  # noqa: E731
    print(f"{name}: mean online {t[:, 0].mean():.4f} offline {t[:, 1].mean():.4f} offline+look {t[:, 2].mean():.4f}; "
          f"look-offline {d1.mean():+.4f} (se {se(d1):.4f}); look-online {d2.mean():+.4f} (se {se(d2):.4f})")


if __name__ == "__main__":
    which = sys.argv[1:] or ["arenas", "hexbug"]
    if "arenas" in which:
        summary("arenas 0-9", arenas(range(10)))
    if "hexbug" in which:
        summary("hexbug", hexbug())
