"""Development runs of research/appearance/rule13.md (arena seeds 0-9 and 4000-4019, the 14 HexBug clips): round 11's
placement in merged blobs (straight-line centres; `merges.py` as of 0ad3166, read from git) against round 13's
(Hermite centres, the package's), patched in one process on the same blobs and look. Not a scoring run.
Usage: dev13.py [arenas,hexbug]. Round 13 was not kept: this compares the two only on a tree with its code
(`git apply research/appearance/round13.patch`); without it both columns are round 11's."""
import tempfile
from pathlib import Path

import scoring

from lookalike.trackers.offline import merges

work = Path(tempfile.mkdtemp(prefix="appearance-dev13-"))
MODES = ("round11", "round13")
ROUND11 = scoring.module_at("0ad3166", "src/lookalike/trackers/offline/merges.py", work)._on_parts


def run(video, n):
    found, fps = scoring.detected(video, n, work)
    return scoring.with_each(found, fps, n, merges, "_on_parts", [ROUND11, merges._on_parts])


if __name__ == "__main__":
    scoring.main(run, MODES, work)
