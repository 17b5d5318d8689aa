"""Development runs of research/appearance/rule11.md (arena seeds 0-9 and 4000-4019, the 14 HexBug clips): round 7's
frame-by-frame placement in merged blobs (`_on_parts` of `appearance.py` as of 423b986, read from git) against one
least-cost path over all frames (round 11, the package's `merges._on_parts`), patched in one process on the same
blobs and look. Not a scoring run. Usage: dev11.py [arenas,hexbug]"""
import tempfile
from pathlib import Path

import scoring

from lookalike.trackers.offline import merges

work = Path(tempfile.mkdtemp(prefix="appearance-dev11-"))
MODES = ("round7", "round11")
FORWARD = scoring.module_at("423b986", "src/lookalike/trackers/offline/appearance.py", work)._on_parts


def run(video, n):
    found, fps = scoring.detected(video, n, work)
    return scoring.with_each(found, fps, n, merges, "_on_parts", [FORWARD, merges._on_parts])


if __name__ == "__main__":
    scoring.main(run, MODES, work)
