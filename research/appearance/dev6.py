"""Development runs of research/appearance/rule6.md (arena seeds 0-9 and 4000-4019, the 14 HexBug clips): round 5
(profiles as the area turns them) against round 6 (turned head first by the motion). Not a scoring run.
Usage: dev6.py [arenas,hexbug]. Round 6 was not kept: this runs only on a tree with its code (`head_first` in
trackers/offline/appearance.py, called first in `assign_identities`, and the profiles' direction as two more columns
of `blob_shapes`), as described in rule6.md."""
import sys
import tempfile
from pathlib import Path

import scoring

import lookalike.trackers.offline.closed_set as closed_set
from lookalike.trackers.offline.appearance import head_first
from lookalike.vision.blob_auto import BOX_TRACKER_PARAMS
from lookalike.vision.blob_shape import LOOK_SIZE

work = Path(tempfile.mkdtemp(prefix="appearance-dev6-"))
MODES = ("round5", "round6")


def run(video, n):
    found, fps = scoring.detected(video, n, work)
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


if __name__ == "__main__":
    which = sys.argv[1].split(",") if len(sys.argv) > 1 else ["arenas", "hexbug"]
    if "arenas" in which:
        seeds = [*range(10), *range(4000, 4020)]
        scoring.summary("arenas 0-9, 4000-4019", scoring.arenas(seeds, run, MODES, work), MODES)
    if "hexbug" in which:
        scoring.summary("hexbug", scoring.hexbug(run, MODES), MODES)
