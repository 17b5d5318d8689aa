"""Development runs of research/appearance/rule8.md (arena seeds 0-9 and 4000-4019, the 14 HexBug clips): round 7
(looks as measured) against round 8 (absolute intensities against the frame's median). Not a scoring run.
Usage: dev8.py [arenas,hexbug]. Round 8 was not kept: this runs only on a tree with its code, as rule8.md says."""
import sys
import tempfile
from pathlib import Path

import scoring

import lookalike.trackers.offline.closed_set as closed_set
from lookalike.trackers.offline.appearance import against_frame_light
from lookalike.vision.blob_auto import BOX_TRACKER_PARAMS

work = Path(tempfile.mkdtemp(prefix="appearance-dev8-"))
MODES = ("round7", "round8")


def run(video, n):
    found, fps = scoring.detected(video, n, work)
    out = []
    for mode in MODES:
        closed_set.against_frame_light = against_frame_light if mode == "round8" else (lambda rows, shapes: shapes)
        try:
            out.append(closed_set.track_closed_set(found.rows, n, fps, n_frames=found.frames,
                                                   online=dict(BOX_TRACKER_PARAMS), shapes=found.shapes,
                                                   parts=found.parts))
        finally:
            closed_set.against_frame_light = against_frame_light
    return out


if __name__ == "__main__":
    which = sys.argv[1].split(",") if len(sys.argv) > 1 else ["arenas", "hexbug"]
    if "arenas" in which:
        seeds = [*range(10), *range(4000, 4020)]
        scoring.summary("arenas 0-9, 4000-4019", scoring.arenas(seeds, run, MODES, work), MODES)
    if "hexbug" in which:
        scoring.summary("hexbug", scoring.hexbug(run, MODES), MODES)
