"""Development runs of research/appearance/rule10.md (arena seeds 0-9 and 4000-4019, the 14 HexBug clips): round 7's
look (a normal on the log look distance, clamped below the "one animal" mean; `appearance.py` as of 423b986, read from
git) against round 10's (the distance a gamma under either hypothesis, no clamp; the package's). Not a scoring run.
Usage: dev10.py [arenas,hexbug]. Round 10 was not kept:
this compares the two only on a tree with its code (`git apply research/appearance/round10.patch`), as rule10.md
says; without it both columns are round 7's."""
import tempfile
from pathlib import Path

import scoring

import lookalike.trackers.offline.appearance as appearance

work = Path(tempfile.mkdtemp(prefix="appearance-dev10-"))
MODES = ("round7", "round10")
BASELINE = "423b986"


ROUND7 = scoring.module_at(BASELINE, "src/lookalike/trackers/offline/appearance.py", work)


def run(video, n):
    found, fps = scoring.detected(video, n, work)
    return scoring.with_looks(found, fps, n, (ROUND7, appearance))


if __name__ == "__main__":
    scoring.main(run, MODES, work)
