"""Development runs of research/appearance/rule15.md (arena seeds 0-9 and 4000-4019, the 14 HexBug clips): round 14
(a merged blob's animals counted from its area) against round 15 (from the identities inside it), switched in one
process on the same blobs and look (the development run switched a flag, since taken out; this patches round 14's
`_on_parts` from git, 761d0df, with the same rows). Not a scoring run. Usage: dev15.py [arenas,hexbug]"""
import tempfile
from pathlib import Path

import scoring

from lookalike.trackers.offline import merges

work = Path(tempfile.mkdtemp(prefix="appearance-dev15-"))
MODES = ("round14", "round15")
ROUND14 = scoring.module_at("761d0df", "src/lookalike/trackers/offline/merges.py", work)._on_parts


def run(video, n):
    found, fps = scoring.detected(video, n, work)
    return scoring.with_each(found, fps, n, merges, "_on_parts", [ROUND14, merges._on_parts])


if __name__ == "__main__":
    scoring.main(run, MODES, work)
