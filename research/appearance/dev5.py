"""Development runs of research/appearance/rule5.md (arena seeds 0-9, the 14 HexBug clips): round 4's default
against the merged blobs' identities placed on their pixel split's centroids (variants A and B here; repair A2 is
the package's own, which rule5.md's run showed equal to this harness's first copy of it). Each reads the parts the
package's detector gives (blobs 1.4x the recent median size); rule5.md's A and B figures split every blob. Not a
scoring run.
Usage: dev5.py [arenas,hexbug] [MODE,MODE...]"""
import math
import sys
import tempfile
from pathlib import Path

import numpy as np
import scoring
from scipy.optimize import linear_sum_assignment

import lookalike.trackers.offline.closed_set as closed_set
from lookalike.trackers.offline.appearance import MERGE_REACH, place_in_merges
from lookalike.vision.blob_auto import BOX_TRACKER_PARAMS

work = Path(tempfile.mkdtemp(prefix="appearance-dev5-"))


def placer(parts, mode):
    def place(rows, measured, merged, *_):
        before = np.array(rows, dtype=float)
        out = place_in_merges(rows, measured, merged)
        loose = np.flatnonzero(~measured)
        frames = before[loose, 0].astype(int)
        last: dict[int, tuple[int, np.ndarray]] = {}
        for row in merged[np.argsort(merged[:, 0], kind="stable")]:
            f, (x0, y0, w, h) = int(row[0]), row[2:6]
            centre, reach = np.array([x0 + w / 2, y0 + h / 2]), MERGE_REACH * math.sqrt(w * h)
            ks = loose[frames == f]
            c = before[ks, 2:4] + before[ks, 4:6] / 2
            inside = np.all(np.abs(c - centre) <= np.array([w, h]) / 2 + reach, axis=1)
            ks, c = ks[inside], c[inside]
            m = len(ks)
            if m not in (2, 3):
                continue
            part = parts[int(row[9])]
            cent = part[:4].reshape(2, 2) if m == 2 else part[4:].reshape(3, 2)
            if np.isnan(cent).any():  # not split: the box's ends stay
                continue
            if mode == "B":
                for i, k in enumerate(ks):
                    prev = last.get(int(before[k, 1]))
                    if prev is not None and prev[0] == f - 1:
                        c[i] = prev[1]
            a, b = linear_sum_assignment(np.linalg.norm(c[:, None] - cent[None], axis=2))
            for i, j in zip(a, b):
                out[ks[i], 2:4] = cent[j] - out[ks[i], 4:6] / 2
                last[int(before[ks[i], 1])] = (f, cent[j])
        return out
    return place


MODES = tuple(sys.argv[2].split(",")) if len(sys.argv) > 2 else ("round4", "A", "B", "A2")


def run(video, n):
    found, fps = scoring.detected(video, n, work)
    out = []
    for mode in MODES:  # A2: the package's own (the parts of its detector, placed by appearance._on_parts)
        closed_set.place_in_merges = place_in_merges if mode in ("round4", "A2") else placer(found.parts, mode)
        try:
            out.append(closed_set.track_closed_set(found.rows, n, fps, n_frames=found.frames,
                                                   online=dict(BOX_TRACKER_PARAMS), shapes=found.shapes,
                                                   parts=found.parts if mode == "A2" else None))
        finally:
            closed_set.place_in_merges = place_in_merges
    return out


if __name__ == "__main__":
    which = sys.argv[1].split(",") if len(sys.argv) > 1 else ["arenas", "hexbug"]
    if "arenas" in which:
        scoring.summary("arenas 0-9", scoring.arenas(range(10), run, MODES, work), MODES)
    if "hexbug" in which:
        scoring.summary("hexbug", scoring.hexbug(run, MODES), MODES)
