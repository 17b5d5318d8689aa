"""Development run of confidence-rule.md: the `--online` rows with the online look, their row confidence without and
with the look term (the shipped weight, no fit), on the 30 development arenas and the 14 HexBug clips. Run from the
repository root: ``OMP_NUM_THREADS=1 .venv/bin/python research/online_look/confidence_dev.py``"""
import sys
import tempfile
from pathlib import Path
from types import SimpleNamespace

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "confidence"))
import look  # noqa: E402
from fit import Result, label_rows  # noqa: E402

from lookalike.trackers.offline.confidence import (  # noqa: E402
    COEFFICIENTS,
    LOOK_COEFFICIENT,
    by_frame_and_id,
    row_features,
)
from lookalike.trackers.offline.online_look import (
    LookIdentities,  # noqa: E402
    shape_lookup,  # noqa: E402
)
from lookalike.trackers.registry import make_tracker  # noqa: E402
from lookalike.types import Detections, Frame  # noqa: E402
from lookalike.types.mot_table import tracks_to_rows  # noqa: E402
from lookalike.vision.blob_auto import BOX_TRACKER_PARAMS  # noqa: E402


def one_online(name, video, n, truth, radius, work):
    """The `--online` rows with the look on ``video``: (result with labels, base logit, look margin)."""
    found, fps = look.detected(video, n, work)
    tracker = LookIdentities(make_tracker("boxtrack", **{**BOX_TRACKER_PARAMS, "max_targets": n}), n, fps,
                             shape_lookup(found.rows, found.shapes, found.frames), keep_margins=True)
    det = found.rows[np.argsort(found.rows[:, 0], kind="stable")]
    bounds = np.searchsorted(det[:, 0], np.arange(1, found.frames + 2))
    out = []
    for k in range(found.frames):
        block = det[bounds[k]:bounds[k + 1]]
        dets = Detections(xywh=block[:, 2:6], score=block[:, 6]) if len(block) else Detections.empty()
        out.append(tracks_to_rows(k, tracker.update(Frame(index=k, time=k / fps, detections=dets))))
    rows = np.vstack(out)
    margin = by_frame_and_id(rows, tracker.margin_rows())
    seq = SimpleNamespace(gt=None, gt_points=truth, length=int(found.frames))
    label, switches = label_rows(seq, rows, radius)
    x = row_features(rows, fps)
    base = COEFFICIENTS[0] + x @ np.asarray(COEFFICIENTS[1:])
    print(f"{name}: rows {len(rows)} right {np.mean(label[label >= 0]):.3f} margin on {np.mean(~np.isnan(margin)):.1%}"
          f" switches {len(switches)}", flush=True)
    return Result(name.split()[0], "online", name, fps, rows, x, label, switches, np.nan), base, margin


if __name__ == "__main__":
    look.one = one_online
    work = Path(sys.argv[1]) if len(sys.argv) > 1 else Path(tempfile.mkdtemp(prefix="online-look-conf-"))
    a = look.arenas([*range(10), *range(4000, 4020)], work)
    h = look.hexbug(work)
    ma = look.measure("arenas (30)", a, LOOK_COEFFICIENT)
    mh = look.measure("hexbug (14)", h, LOOK_COEFFICIENT)
    kept = ma["with the look"] < ma["without the look"] and mh["with the look"] < mh["without the look"]
    print(f"keep rule: {'met: kept' if kept else 'not met: not kept'}")
