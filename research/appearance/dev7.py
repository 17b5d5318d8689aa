"""Development runs of research/appearance/rule7.md (arena seeds 0-9 and 4000-4019, the 14 HexBug clips): the
offline closed set with the look's log-likelihood ratios weighed 1, 1.5, 2 and 3 against motion. Not a scoring run.
Usage: dev7.py [arenas,hexbug]"""
import tempfile
from pathlib import Path

import scoring

import lookalike.trackers.offline.appearance as appearance

work = Path(tempfile.mkdtemp(prefix="appearance-dev7-"))
WEIGHTS = (1.0, 1.5, 2.0, 3.0)
MODES = tuple(f"w={w:g}" for w in WEIGHTS)


def run(video, n):
    found, fps = scoring.detected(video, n, work)
    return scoring.with_each(found, fps, n, appearance, "LOOK_WEIGHT", WEIGHTS)


if __name__ == "__main__":
    scoring.main(run, MODES, work)
