"""Round 4 (rule4.md): the threshold on the share of non-single-animal rows above which the online closed set is
written, chosen by leave-one-HexBug-clip-out. Inputs are fixed figures of round 3's runs (rule4.md) and the shares
measured here from the cached blob detections. Run from the repository root: python research/appearance/guard.py"""

import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "benchmarks"))
from _common import SHARED_DATA  # noqa: E402

from lookalike.bench.datasets import read_hexbug_points  # noqa: E402
from lookalike.io.arena_files import write_arena  # noqa: E402
from lookalike.io.video_frames import source_frames  # noqa: E402
from lookalike.pipeline.blob_detections import auto_blob_config, cached_blob_detections  # noqa: E402
from lookalike.trackers.offline.appearance import single_rows  # noqa: E402
from lookalike.trackers.offline.closed_set import online_rows  # noqa: E402
from lookalike.vision.blob_auto import BOX_TRACKER_PARAMS  # noqa: E402

# IDF1 (%) of round 3: `unseen_commands.py --only hexbug` (online = --targets N --online, default = --targets N)
HEXBUG = {"training010": (64.53, 80.77), "training035": (81.55, 77.98), "training042": (62.82, 80.65),
          "training046": (84.74, 91.49), "training047": (58.48, 85.08), "training049": (41.75, 56.72),
          "training051": (54.62, 57.03), "training054": (82.89, 99.67), "training064": (37.63, 77.05),
          "training068": (56.12, 79.04), "training069": (19.62, 14.52), "training088": (35.76, 15.14),
          "training09": (68.91, 95.99), "training097": (59.40, 37.62)}
# development arenas 0-9: `track --online` and round 3's default (research/appearance/rule3.md's run)
ARENAS = {s: (100 * a, 100 * b) for s, (a, b) in enumerate(zip(
    [0.8499, 0.8308, 0.6018, 0.834, 0.8998, 0.6773, 0.8308, 0.7589, 0.7256, 0.5967],
    [0.986, 0.9744, 0.9852, 0.992, 0.9867, 0.9915, 0.9905, 0.9772, 0.994, 0.9665]))}


def share(video: Path, n: int) -> float:
    """Share of the online pass's rows whose blob is not one animal's size."""
    config, _ = auto_blob_config(video, [], n)
    found = cached_blob_detections(video, config)
    fps = source_frames(video)[2] or 25.0
    on = online_rows(found.rows, fps, found.frames, index=True, **{"n_init": 1, **BOX_TRACKER_PARAMS})
    return float(1 - single_rows(on, found.shapes).mean())


def choose(train: list[tuple[str, float, float, float]]) -> float:
    """T by rule4.md: train rows (dataset, share, online, default)."""
    shares = sorted({s for _, s, _, _ in train})
    candidates = [(a + b) / 2 for a, b in zip(shares, shares[1:])] + [np.inf]

    def objective(t: float) -> float:
        per = {}
        for d, s, on, de in train:
            per.setdefault(d, []).append(on if s > t else de)
        return float(np.mean([np.mean(v) for v in per.values()]))

    scores = np.array([objective(t) for t in candidates])
    tied = [t for t, v in zip(candidates, scores) if v >= scores.max() - 1e-9]
    return tied[(len(tied) - 1) // 2]


def main() -> None:
    rows = []
    for name, (on, de) in HEXBUG.items():
        video = SHARED_DATA / "hexbug" / f"{name}.mp4"
        img = next(iter(source_frames(video)[0]))
        n = len(np.unique(read_hexbug_points(video.with_suffix(".csv"), (img.shape[1], img.shape[0]))[1]))
        rows.append(("hexbug", share(video, n), on, de, name))
    for seed, (on, de) in ARENAS.items():
        files = write_arena(Path("/tmp/lookalike-guard") / f"arena{seed}", seed=seed)
        rows.append(("arena", share(files.video, 8), on, de, f"arena {seed}"))
    for r in rows:
        print(f"{r[4]:<12} share {r[1]:.3f}  online {r[2]:6.2f}  default {r[3]:6.2f}")
    left, diffs = [], []
    for k, r in enumerate(rows):
        if r[0] != "hexbug":
            continue
        t = choose([x[:4] for j, x in enumerate(rows) if j != k])
        got = r[2] if r[1] > t else r[3]
        left.append(got)
        diffs.append(got - r[3])
        print(f"left out {r[4]:<12} T {t:.3f} -> {'online' if r[1] > t else 'default'} {got:.2f}")
    se = float(np.std(diffs, ddof=1) / np.sqrt(len(diffs)))
    hex_rows = [r for r in rows if r[0] == "hexbug"]
    print(f"left-out HexBug mean IDF1 {np.mean(left):.2f} (default {np.mean([r[3] for r in hex_rows]):.2f}, online "
          f"{np.mean([r[2] for r in hex_rows]):.2f}); difference {np.mean(diffs):+.2f} (se {se:.2f})")
    t = choose([x[:4] for x in rows])
    print(f"shipped T (all clips and arenas): {t:.3f}; arenas falling back: "
          f"{[r[4] for r in rows if r[0] == 'arena' and r[1] > t]}")


if __name__ == "__main__":
    main()
