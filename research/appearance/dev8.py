"""Development runs of research/appearance/rule8.md (arena seeds 0-9 and 4000-4019, the 14 HexBug clips): round 7
(looks as measured) against round 8 (absolute intensities against the frame's median). Not a scoring run.
Usage: dev8.py [arenas,hexbug]. Round 8 was not kept: this runs only on a tree with its code, as rule8.md says."""
import tempfile
from pathlib import Path

import scoring

import lookalike.trackers.offline.closed_set as closed_set
from lookalike.trackers.offline.appearance import against_frame_light

work = Path(tempfile.mkdtemp(prefix="appearance-dev8-"))
MODES = ("round7", "round8")


def run(video, n):
    found, fps = scoring.detected(video, n, work)
    return scoring.with_each(found, fps, n, closed_set, "against_frame_light",
                             [lambda rows, shapes: shapes, against_frame_light])


if __name__ == "__main__":
    scoring.main(run, MODES, work)
