"""Development runs of research/appearance/rule9.md (arena seeds 0-9 and 4000-4019, the 14 HexBug clips): round 7's
look (one log distance per link, its `appearance.py` as of 34e0414, read from git) against round 9's (the evidence
direction by direction, the package's). Not a scoring run. Usage: dev9.py [arenas,hexbug]. Round 9 was not kept:
this compares the two only on a tree with its code (`git apply research/appearance/round9.patch`), as rule9.md
says; without it both columns are round 7's."""
import importlib.util
import subprocess
import sys
import tempfile
from pathlib import Path

import scoring

import lookalike.trackers.offline.appearance as appearance
import lookalike.trackers.offline.closed_set as closed_set

work = Path(tempfile.mkdtemp(prefix="appearance-dev9-"))
MODES = ("round7", "round9")
BASELINE = "34e0414"


def baseline_module():
    """Round 7's appearance module, from git, under a name of its own."""
    root = Path(__file__).resolve().parents[2]
    text = subprocess.run(["git", "-C", str(root), "show", f"{BASELINE}:src/lookalike/trackers/offline/appearance.py"],
                          capture_output=True, text=True, check=True).stdout
    path = work / "appearance_round7.py"
    path.write_text(text)
    spec = importlib.util.spec_from_file_location("appearance_round7", path)
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module
    spec.loader.exec_module(module)
    return module


ROUND7 = baseline_module()


def run(video, n):
    found, fps = scoring.detected(video, n, work)
    out = []
    for module in (ROUND7, appearance):
        kept = closed_set.with_appearance
        closed_set.with_appearance = module.with_appearance
        try:
            out += scoring.with_each(found, fps, n, closed_set, "fit_identity_space", [module.fit_identity_space])
        finally:
            closed_set.with_appearance = kept
    return out


if __name__ == "__main__":
    scoring.main(run, MODES, work)
