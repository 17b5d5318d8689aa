"""Development runs of research/appearance/rule17.md (arena seeds 0-9 and 4000-4019, the 14 HexBug clips): round 16's
parts (2fb8f61's `blob_parts`, read from git and patched into `blob_shape`) against the mixture started from both
k-means splits, in one process, each arm detecting through a cache folder of its own. Rows and shape vectors are the
same in both; only the parts differ. Not a scoring run. Usage: dev17.py [arenas,hexbug]"""
import tempfile
from pathlib import Path

import numpy as np
import scoring

from lookalike.io.video_frames import source_frames
from lookalike.pipeline.blob_detections import auto_blob_config, cached_blob_detections
from lookalike.trackers.offline.closed_set import track_closed_set
from lookalike.vision import blob_shape
from lookalike.vision.blob_auto import BOX_TRACKER_PARAMS

work = Path(tempfile.mkdtemp(prefix="appearance-dev17-"))
MODES = ("round16", "two-starts")
PARTS = {"round16": scoring.module_at("2fb8f61", "src/lookalike/vision/blob_shape.py", work).blob_parts,
         "two-starts": blob_shape.blob_parts}


def run(video, n):
    config, fps = auto_blob_config(video, [], n, cache=work / "cache")[0], source_frames(video)[2] or 25.0
    out, rows = [], None
    try:
        for mode in MODES:
            blob_shape.blob_parts = PARTS[mode]
            found = cached_blob_detections(video, config, cache=work / f"cache-{mode}")
            assert rows is None or np.array_equal(rows, found.rows)
            rows = found.rows
            out.append(track_closed_set(found.rows, n, fps, n_frames=found.frames, online=dict(BOX_TRACKER_PARAMS),
                                        shapes=found.shapes, parts=found.parts))
    finally:
        blob_shape.blob_parts = PARTS["two-starts"]
    return out


if __name__ == "__main__":
    scoring.main(run, MODES, work)
