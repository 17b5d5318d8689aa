"""Development runs of research/appearance/rule17.md (arena seeds 0-9 and 4000-4019, the 14 HexBug clips): round 16's
parts (2fb8f61's `blob_parts`, read from git and patched into `blob_shape`) against the mixture started from both
k-means splits, in one process, each arm detecting through a cache folder of its own. Rows and shape vectors are the
same in both; only the parts differ. Not a scoring run. Usage: dev17.py [arenas,hexbug]"""
import tempfile
from pathlib import Path

import scoring

from lookalike.vision import blob_shape

work = Path(tempfile.mkdtemp(prefix="appearance-dev17-"))
MODES = ("round16", "two-starts")
PARTS = {"round16": scoring.module_at("2fb8f61", "src/lookalike/vision/blob_shape.py", work).blob_parts,
         "two-starts": blob_shape.blob_parts}


def run(video, n):
    return scoring.with_parts(video, n, work, PARTS)


if __name__ == "__main__":
    scoring.main(run, MODES, work)
