"""Development runs of research/appearance/rule6.md (arena seeds 0-9 and 4000-4019, the 14 HexBug clips): round 5
(profiles as the area turns them) against round 6 (turned head first by the motion). Not a scoring run.
Usage: dev6.py [arenas,hexbug]. Round 6 was not kept: this runs only on a tree with its code (`head_first` in
trackers/offline/appearance.py, called first in `assign_identities`, and the profiles' direction as two more columns
of `blob_shapes`), as described in rule6.md."""
import tempfile
from pathlib import Path

import scoring

import lookalike.trackers.offline.closed_set as closed_set
from lookalike.trackers.offline.appearance import head_first
from lookalike.vision.blob_shape import LOOK_SIZE

work = Path(tempfile.mkdtemp(prefix="appearance-dev6-"))
MODES = ("round5", "round6")


def run(video, n):
    found, fps = scoring.detected(video, n, work)
    return scoring.with_each(found, fps, n, closed_set, "head_first",
                             [lambda rows, shapes: shapes[:, :LOOK_SIZE], head_first])


if __name__ == "__main__":
    scoring.main(run, MODES, work)
