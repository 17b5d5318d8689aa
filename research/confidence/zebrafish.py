"""The shipped confidence measured once on the zebrafish video (``rule.md``'s addendum): idtracker.ai's reference,
15 px. Run from the repository root after writing the two results::

    V=../shared/data/zebrafish/test_A.avi
    lookalike track --video $V --detector blob -t boxtrack --targets 8 -o /tmp/zf/online.txt
    lookalike track --video $V --detector blob -t boxtrack --targets 8 --offline -o /tmp/zf/offline.txt
    .venv/bin/python research/confidence/zebrafish.py /tmp/zf | tee research/confidence/zebrafish-result.txt
"""

from __future__ import annotations

import sys
from pathlib import Path
from types import SimpleNamespace

import numpy as np
from fit import ROOT, THRESHOLD, Result, auc, ece, label_rows, switch_share

from lookalike.io import read_mot
from lookalike.io.video_frames import source_frames
from lookalike.trackers.offline.confidence import assignment_confidence, row_features

RADIUS_PX = 15.0


def main(folder: Path) -> None:
    video = ROOT.parent / "shared" / "data" / "zebrafish" / "test_A.avi"
    ref = np.loadtxt(video.with_name("idtracker_test_A.csv"), delimiter=",", skiprows=1).reshape(-1, 4)
    _, length, fps = source_frames(video)
    seq = SimpleNamespace(gt=None, gt_points=(ref[:, 0].astype(int) + 1, ref[:, 1].astype(int), ref[:, 2:4]),
                          length=int(length))
    print(f"zebrafish/test_A.avi: {length} frames at {fps:.2f} frames/s; reference rows {len(ref)}; "
          f"radius {RADIUS_PX} px")
    results, probs = [], []
    for kind in ("online", "offline"):
        t = read_mot(folder / f"{kind}.txt")
        rows = np.column_stack([t.frame, t.track_id, t.xywh, t.conf, -np.ones((len(t), 3))])
        label, switches = label_rows(seq, rows, RADIUS_PX)
        p = assignment_confidence(rows, fps)
        results.append(Result("zebrafish", kind, "test_A", fps, rows, row_features(rows, fps), label, switches, np.nan))
        probs.append(p)
        y = label.astype(float)
        inside, total, share = switch_share([results[-1]], [p], THRESHOLD)
        print(f"{kind:8s} rows {len(rows):5d} right {y.mean():.3f} mean confidence {p.mean():.3f} "
              f"ECE {ece(p, y)[0]:.3f} AUC {auc(p, y):.3f} switches in a range {inside}/{total} "
              f"rows in a range {share:.1%}")
    p = np.concatenate(probs)
    y = np.concatenate([r.label for r in results]).astype(float)
    e, mp, my, n = ece(p, y)
    inside, total, share = switch_share(results, probs, THRESHOLD)
    print(f"both     rows {len(y):5d} right {y.mean():.3f} ECE {e:.3f} switches in a range {inside}/{total} "
          f"= {inside / max(total, 1):.1%} rows in a range {share:.1%}")
    print("bins (mean confidence, share right, rows): " + "; ".join(
        f"{a:.2f} {b:.2f} {int(c)}" for a, b, c in zip(mp, my, n) if c))


if __name__ == "__main__":
    main(Path(sys.argv[1]))
