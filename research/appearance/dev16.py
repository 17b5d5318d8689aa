"""Development runs of research/appearance/rule16.md (arena seeds 0-9 and 4000-4019, the 14 HexBug clips): the
k-means parts (1d0021c's `blob_parts`) against the parts refined by a Gaussian mixture (634f3bb's, with the repair),
both read from git, in one process, each arm detecting through a cache folder of its own (`scoring.with_parts`; the
development run switched a flag, since taken out). Rows and shape vectors are the same in both; only the parts
differ. Not a scoring run. Usage: dev16.py [arenas,hexbug]"""
import tempfile
from pathlib import Path

import scoring

work = Path(tempfile.mkdtemp(prefix="appearance-dev16-"))
MODES = ("kmeans", "mixture")
PARTS = {"kmeans": scoring.module_at("1d0021c", "src/lookalike/vision/blob_shape.py", work).blob_parts,
         "mixture": scoring.module_at("634f3bb", "src/lookalike/vision/blob_shape.py", work).blob_parts}


def run(video, n):
    return scoring.with_parts(video, n, work, PARTS)


if __name__ == "__main__":
    scoring.main(run, MODES, work)
