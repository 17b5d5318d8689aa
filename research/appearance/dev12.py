"""Development runs of research/appearance/rule12.md (arena seeds 0-9 and 4000-4019, the 14 HexBug clips): round 7's
look (`appearance.py` as of 6107a41, read from git) against round 12's (the same evidence plus, on links with
competitors, the ratio that the later tracklet continues the earlier one rather than the animal it could be confused
with, along Fisher's direction between those two; the package's). Not a scoring run. Usage: dev12.py [arenas,hexbug].
Round 12 was not kept: this compares the two only on a tree with its code (`git apply
research/appearance/round12.patch`), as rule12.md says; without it both columns are round 7's look."""
import tempfile
from pathlib import Path

import scoring

import lookalike.trackers.offline.appearance as appearance
import lookalike.trackers.offline.closed_set as closed_set

work = Path(tempfile.mkdtemp(prefix="appearance-dev12-"))
MODES = ("round11", "round12")
BASELINE = "6107a41"


ROUND11 = scoring.module_at(BASELINE, "src/lookalike/trackers/offline/appearance.py", work)


def run(video, n):
    found, fps = scoring.detected(video, n, work)
    out = []
    for module in (ROUND11, appearance):
        kept = closed_set.with_appearance
        closed_set.with_appearance = module.with_appearance
        try:
            out += scoring.with_each(found, fps, n, closed_set, "fit_identity_space", [module.fit_identity_space])
        finally:
            closed_set.with_appearance = kept
    return out


if __name__ == "__main__":
    scoring.main(run, MODES, work)
