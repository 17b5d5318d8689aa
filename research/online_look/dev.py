"""Development run of rule.md: the `--online` rows (boxtrack with `max_targets`, as the command runs it) without and
with the look layer at each threshold (the development run scored `layer.py`, in git at 345c696; this runs the
shipped `SlotLooks`, which gives the same ids), on the 30 development arenas and the 14 HexBug clips. Run from the
repository root: ``OMP_NUM_THREADS=1 .venv/bin/python research/online_look/dev.py [arenas,hexbug] [SEEDS]``"""
import sys
import tempfile
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "appearance"))
import scoring  # noqa: E402

from lookalike.trackers.offline.online_look import SlotLooks  # noqa: E402
from lookalike.trackers.registry import make_tracker  # noqa: E402
from lookalike.types import Detections, Frame  # noqa: E402
from lookalike.vision.blob_auto import BOX_TRACKER_PARAMS  # noqa: E402

work = Path(tempfile.mkdtemp(prefix="online-look-dev-"))
THRESHOLDS = (0.5, 1.0, 2.0)
MODES = ("online", *(f"look{t}" for t in THRESHOLDS))


def online(found, fps, n):
    """Reported rows (frame, slot, box) and each row's shape vector (NaN when coasting)."""
    tracker = make_tracker("boxtrack", **{**BOX_TRACKER_PARAMS, "max_targets": n})
    det = found.rows
    order = np.argsort(det[:, 0], kind="stable")
    det, shapes = det[order], found.shapes[order]
    bounds = np.searchsorted(det[:, 0], np.arange(1, found.frames + 2))
    rows, vecs = [], []
    for k in range(found.frames):
        block = det[bounds[k]:bounds[k + 1]]
        dets = Detections(xywh=block[:, 2:6], score=block[:, 6]) if len(block) else Detections.empty()
        for t in tracker.update(Frame(index=k, time=k / fps, detections=dets)):
            if t.xywh is None:
                continue
            rows.append([k + 1, t.track_id, *t.xywh])
            i = t.detection_index
            vecs.append(shapes[bounds[k] + i] if i is not None and i >= 0 else np.full(shapes.shape[1], np.nan))
    return np.array(rows, dtype=float).reshape(-1, 6), np.array(vecs)


def relabel(rows, vecs, fps, threshold):
    layer = SlotLooks(int(rows[:, 1].max()), fps, threshold)
    out = rows.copy()
    starts = np.flatnonzero(np.r_[True, np.diff(rows[:, 0]) != 0, True])
    for a, b in zip(starts[:-1], starts[1:]):
        out[a:b, 1] = layer.update(rows[a:b, 1].astype(int), rows[a:b, 2:6], vecs[a:b])
    return out, layer.changes


def run(video, n):
    found, fps = scoring.detected(video, n, work)
    rows, vecs = online(found, fps, n)
    out, changes = [rows], []
    for t in THRESHOLDS:
        r, c = relabel(rows, vecs, fps, t)
        out.append(r)
        changes.append(c)
    print(f"  re-assignments per threshold: {changes}", flush=True)
    return out


if __name__ == "__main__":
    seeds = [int(s) for s in sys.argv[2].split(",")] if len(sys.argv) > 2 else (*range(10), *range(4000, 4020))
    scoring.main(run, MODES, work, seeds=seeds)
