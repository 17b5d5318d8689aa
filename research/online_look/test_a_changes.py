"""Diagnosis only (nothing chosen on it): how many times the look re-assigned slots on test_A with `--online`, and why
not more (pieces finished, groups judged). Run from the repository root with OMP_NUM_THREADS=1."""
import sys
import tempfile
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "appearance"))
import scoring  # noqa: E402

from lookalike.trackers.offline import online_look  # noqa: E402
from lookalike.trackers.offline.closed_set import online_rows  # noqa: E402
from lookalike.vision.blob_auto import BOX_TRACKER_PARAMS  # noqa: E402

video = scoring.SHARED_DATA / "zebrafish" / "test_A.avi"
found, fps = scoring.detected(video, 8, Path(tempfile.mkdtemp()))
made = []
kept = online_look.LookIdentities.__init__


def spy(self, *args, **kwargs):
    kept(self, *args, **kwargs)
    made.append(self)


online_look.LookIdentities.__init__ = spy
online_rows(found.rows, fps, found.frames, reported=True, shapes=found.shapes,
            **{**BOX_TRACKER_PARAMS, "max_targets": 8})
looks = made[0].looks
sizes = [len(s) for _, s, _ in looks.done]
print(f"frames {looks.frame}, re-assignments {looks.changes}, finished pieces {len(looks.done)} "
      f"(median {np.median(sizes) if sizes else 0} rows), map fitted: {looks.space is not None}")
