"""The look in the row confidence (``look-rule.md``): the development run (two folds, arenas and HexBug) or the
confirmation (fresh arenas and test_A with the weight given). Run from the repository root::

    OMP_NUM_THREADS=1 .venv/bin/python research/confidence/look.py dev | tee research/confidence/look-dev.txt
    OMP_NUM_THREADS=1 .venv/bin/python research/confidence/look.py confirm W | tee research/confidence/look-confirm.txt
"""

from __future__ import annotations

import sys
import tempfile
from pathlib import Path
from types import SimpleNamespace

import numpy as np
from fit import ROOT, THRESHOLD, Result, auc, ece, label_rows, switch_share

sys.path.insert(0, str(ROOT / "research" / "appearance"))
from scoring import detected  # noqa: E402

from lookalike.bench.datasets import read_hexbug_points  # noqa: E402
from lookalike.io.arena_files import write_arena  # noqa: E402
from lookalike.io.video_frames import source_frames  # noqa: E402
from lookalike.trackers.offline.closed_set import closed_set_and_look  # noqa: E402
from lookalike.trackers.offline.confidence import COEFFICIENTS, logistic, row_features  # noqa: E402
from lookalike.vision.blob_auto import BOX_TRACKER_PARAMS  # noqa: E402

DATA = ROOT.parent / "shared" / "data"


def one(name: str, video: Path, n: int, truth: tuple[np.ndarray, np.ndarray, np.ndarray], radius: float,
        work: Path) -> tuple[Result, np.ndarray, np.ndarray]:
    """The closed set on ``video`` as the default command runs it: (result with labels, base logit, look margin)."""
    found, fps = detected(video, n, work)
    rows, look = closed_set_and_look(found.rows, n, fps, n_frames=found.frames, online=dict(BOX_TRACKER_PARAMS),
                                     shapes=found.shapes, parts=found.parts)
    seq = SimpleNamespace(gt=None, gt_points=truth, length=int(found.frames))
    label, switches = label_rows(seq, rows, radius)
    x = row_features(rows, fps)
    base = COEFFICIENTS[0] + x @ np.asarray(COEFFICIENTS[1:])
    margin = np.full(len(rows), np.nan) if look is None else look
    print(f"{name}: rows {len(rows)} right {np.mean(label[label >= 0]):.3f} look on {np.mean(~np.isnan(margin)):.1%} "
          f"switches {len(switches)}", flush=True)
    return Result(name.split()[0], "closed", name, fps, rows, x, label, switches, np.nan), base, margin


def arenas(seeds: list[int], work: Path) -> list[tuple[Result, np.ndarray, np.ndarray]]:
    out = []
    for seed in seeds:
        files = write_arena(work / f"arena{seed}", seed=seed)
        t = np.loadtxt(files.gt, delimiter=",", ndmin=2)
        truth = (t[:, 0].astype(int), t[:, 1].astype(int), t[:, 2:4] + t[:, 4:6] / 2)
        out.append(one(f"arenas {seed}", files.video, len(np.unique(t[:, 1])), truth, 15.0, work))
    return out


def hexbug(work: Path) -> list[tuple[Result, np.ndarray, np.ndarray]]:
    out = []
    for video in sorted((DATA / "hexbug").glob("*.mp4")):
        img = next(iter(source_frames(video)[0]))
        frame, ids, xy = read_hexbug_points(video.with_suffix(".csv"), (img.shape[1], img.shape[0]))
        out.append(one(f"hexbug {video.stem}", video, len(np.unique(ids)), (frame, ids, xy), 120.0, work))
    return out


def test_a(work: Path) -> list[tuple[Result, np.ndarray, np.ndarray]]:
    video = DATA / "zebrafish" / "test_A.avi"
    ref = np.loadtxt(video.with_name("idtracker_test_A.csv"), delimiter=",", skiprows=1).reshape(-1, 4)
    return [one("zebrafish test_A", video, 8, (ref[:, 0].astype(int) + 1, ref[:, 1].astype(int), ref[:, 2:4]),
                15.0, work)]


def fit_weight(items: list[tuple[Result, np.ndarray, np.ndarray]]) -> float:
    """The look's weight by Newton's method, each dataset (first word of the name) the same total weight."""
    sets = sorted({r.dataset for r, _, _ in items})
    z, m, y, v = [], [], [], []
    for d in sets:
        part = [(r, b, k) for r, b, k in items if r.dataset == d]
        keep = [r.label >= 0 for r, _, _ in part]
        z.append(np.concatenate([b[s] for (_, b, _), s in zip(part, keep)]))
        m.append(np.concatenate([np.nan_to_num(k[s]) for (_, _, k), s in zip(part, keep)]))
        y.append(np.concatenate([r.label[s] for (r, _, _), s in zip(part, keep)]).astype(float))
        v.append(np.full(len(y[-1]), 1.0 / len(y[-1])))
    zz, mm, yy, vv = map(np.concatenate, (z, m, y, v))
    w = 0.0
    for _ in range(50):
        p = 1.0 / (1.0 + np.exp(-np.clip(zz + w * mm, -50, 50)))
        grad, hess = float(np.sum(vv * (yy - p) * mm)), float(np.sum(vv * p * (1 - p) * mm * mm))
        if hess <= 0:
            break
        w += grad / hess
        if abs(grad / hess) < 1e-10:
            break
    return w


def measure(label: str, items: list[tuple[Result, np.ndarray, np.ndarray]], w: float) -> dict[str, float]:
    out = {}
    for arm, weight in (("without the look", 0.0), ("with the look", w)):
        probs = [logistic(np.column_stack([b + weight * np.nan_to_num(k)]), (0.0, 1.0)) for _, b, k in items]
        keep = [r.label >= 0 for r, _, _ in items]
        p = np.concatenate([q[s] for q, s in zip(probs, keep)])
        y = np.concatenate([r.label[s] for (r, _, _), s in zip(items, keep)]).astype(float)
        e = ece(p, y)[0]
        inside, total, share = switch_share([r for r, _, _ in items], probs, THRESHOLD)
        print(f"  {label} {arm:17s} rows {len(y)} right {y.mean():.3f} mean p {p.mean():.3f} ECE {e:.3f} "
              f"AUC {auc(p, y):.3f} switches in a range {inside}/{total} rows in a range {share:.1%}")
        out[arm] = e
        out[arm + " switches"] = inside / max(total, 1)
    return out


def main() -> None:
    work = Path(tempfile.mkdtemp(prefix="look-conf-"))
    if sys.argv[1] == "dev":
        a = arenas([*range(10), *range(4000, 4020)], work)
        h = hexbug(work)
        kept = True
        for train, test, name in ((a, h, "hexbug"), (h, a, "arenas")):
            w = fit_weight(train)
            print(f"fold: fitted without {name}: w = {w:.4f}")
            m = measure(f"{name} left out", test, w)
            kept &= w > 0 and m["with the look"] < m["without the look"] and \
                m["with the look switches"] >= m["without the look switches"]
        w = fit_weight(a + h)
        print(f"fitted on both: w = {w:.4f}; keep rule {'met: kept' if kept else 'not met: not kept'}")
    else:
        w = float(sys.argv[2])
        measure("fresh arenas 11000-11019", arenas(list(range(11000, 11020)), work), w)
        measure("test_A (idtracker.ai, 15 px)", test_a(work), w)


if __name__ == "__main__":
    main()
