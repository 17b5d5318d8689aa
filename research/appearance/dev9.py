"""Development runs of research/appearance/rule9.md (arena seeds 0-9 and 4000-4019, the 14 HexBug clips): round 7's
look (one log distance per link, its `appearance.py` as of 34e0414, read from git) against round 9's (the evidence
direction by direction, the package's). Not a scoring run. Usage: dev9.py [arenas,hexbug]. Round 9 was not kept:
this compares the two only on a tree with its code (`git apply research/appearance/round9.patch`), as rule9.md
says; without it both columns are round 7's."""
import tempfile
from pathlib import Path

import scoring

import lookalike.trackers.offline.appearance as appearance

work = Path(tempfile.mkdtemp(prefix="appearance-dev9-"))
MODES = ("round7", "round9")
BASELINE = "34e0414"


ROUND7 = scoring.module_at(BASELINE, "src/lookalike/trackers/offline/appearance.py", work)


def run(video, n):
    found, fps = scoring.detected(video, n, work)
    return scoring.with_looks(found, fps, n, (ROUND7, appearance))


if __name__ == "__main__":
    scoring.main(run, MODES, work)
