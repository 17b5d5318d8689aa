"""Development runs of research/appearance/rule7.md (arena seeds 0-9 and 4000-4019, the 14 HexBug clips): the
offline closed set with the look's log-likelihood ratios weighed 1, 1.5, 2 and 3 against motion. Not a scoring run.
Usage: dev7.py [arenas,hexbug]"""
import sys
import tempfile
from pathlib import Path

import scoring

import lookalike.trackers.offline.appearance as appearance
from lookalike.trackers.offline.closed_set import track_closed_set
from lookalike.vision.blob_auto import BOX_TRACKER_PARAMS

work = Path(tempfile.mkdtemp(prefix="appearance-dev7-"))
WEIGHTS = (1.0, 1.5, 2.0, 3.0)
MODES = tuple(f"w={w:g}" for w in WEIGHTS)


def run(video, n):
    found, fps = scoring.detected(video, n, work)
    out = []
    for w in WEIGHTS:
        appearance.LOOK_WEIGHT = w
        try:
            out.append(track_closed_set(found.rows, n, fps, n_frames=found.frames, online=dict(BOX_TRACKER_PARAMS),
                                        shapes=found.shapes, parts=found.parts))
        finally:
            appearance.LOOK_WEIGHT = 1.0
    return out


if __name__ == "__main__":
    which = sys.argv[1].split(",") if len(sys.argv) > 1 else ["arenas", "hexbug"]
    if "arenas" in which:
        seeds = [*range(10), *range(4000, 4020)]
        scoring.summary("arenas 0-9, 4000-4019", scoring.arenas(seeds, run, MODES, work), MODES)
    if "hexbug" in which:
        scoring.summary("hexbug", scoring.hexbug(run, MODES), MODES)
