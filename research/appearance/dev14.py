"""Development runs of research/appearance/rule14.md (arena seeds 0-9 and 4000-4019, the 14 HexBug clips): round 11
(identities stop where a merge runs to the video's end) against round 14 (they stay in that merged blob), switched in
one process on the same blobs and look (the development run switched a flag, since taken out; this patches the
closed set's `hold_in_merges`, with the same rows). Not a scoring run. Usage: dev14.py [arenas,hexbug]"""
import tempfile
from pathlib import Path

import scoring

import lookalike.trackers.offline.closed_set as closed_set
from lookalike.trackers.offline.merges import hold_in_merges

work = Path(tempfile.mkdtemp(prefix="appearance-dev14-"))
MODES = ("round11", "round14")


def run(video, n):
    found, fps = scoring.detected(video, n, work)
    return scoring.with_each(found, fps, n, closed_set, "hold_in_merges", [lambda rows, pieces: rows, hold_in_merges])


if __name__ == "__main__":
    scoring.main(run, MODES, work)
