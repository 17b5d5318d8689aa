"""Development runs of research/appearance/rule5.md (arena seeds 0-9, the 14 HexBug clips): round 4's default
against the merged blobs' identities placed on their pixel split's centroids (variants A and B, repair A2; "shipped":
the package's own). Not a scoring run.
Usage: dev5.py [arenas,hexbug] [MODE,MODE...]"""
import math
import sys
import tempfile
from pathlib import Path

import numpy as np
import scoring
from scipy.optimize import linear_sum_assignment

import lookalike.trackers.offline.closed_set as closed_set
import lookalike.vision.blob_shape as blob_shape
from lookalike.io.video_frames import source_frames
from lookalike.pipeline.blob_detections import auto_blob_config, blob_detections
from lookalike.trackers.offline.appearance import MERGE_REACH, place_in_merges
from lookalike.vision.blob_auto import BOX_TRACKER_PARAMS

work = Path(tempfile.mkdtemp(prefix="appearance-dev5-"))
_collected: list[np.ndarray] = []
_plain_shapes = blob_shape.blob_shapes


_areas: list[float] = []
GATE = 1.4  # parts only for blobs this many times the median area of the last 512 blobs (the current frame's too)


def _shapes_and_parts(labels, stats, keep, difference, image):
    _areas.extend(float(stats[k, 4]) for k in keep)
    del _areas[:-512]
    reference = float(np.median(_areas))
    for k in keep:
        x, y, w, h = (int(v) for v in stats[k, :4])
        if stats[k, 4] < GATE * reference:
            _collected.append(np.full(blob_shape.PART_SIZE, np.nan))
            continue
        ys, xs = np.nonzero(labels[y:y + h, x:x + w] == k)
        _collected.append(blob_shape.blob_parts(xs + x, ys + y))
    return _plain_shapes(labels, stats, keep, difference, image)


def detections_with_parts(video):
    config, _ = auto_blob_config(video, [], N[0])
    _collected.clear()
    _areas.clear()
    blob_shape.blob_shapes = _shapes_and_parts
    try:
        found = blob_detections(video, config)
    finally:
        blob_shape.blob_shapes = _plain_shapes
    parts = np.array(_collected).reshape(-1, blob_shape.PART_SIZE)
    assert len(parts) == len(found.rows)
    return found, parts


def placer(parts, mode, areas=None):
    if mode == "A2":
        return frame_placer(parts, areas)

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


def frame_placer(parts, areas):
    """Repair A2: per frame, every interpolated identity near a merged blob against all the parts of the frame's
    merged blobs (2 or 3 per blob by its area over the median blob's), cost the distance to the identity's
    interpolated centre plus that to its part in the previous frame (the interpolated centre again when it had
    none); an identity farther than one blob size outside a blob's box cannot take its parts."""
    single = float(np.median(areas))

    def place(rows, measured, merged, *_):
        before = np.array(rows, dtype=float)
        out = place_in_merges(rows, measured, merged)
        loose = np.flatnonzero(~measured)
        frames = before[loose, 0].astype(int)
        last: dict[int, tuple[int, np.ndarray]] = {}
        order = merged[np.argsort(merged[:, 0], kind="stable")]
        for f in np.unique(order[:, 0]).astype(int):
            blobs = order[order[:, 0] == f]
            ks = loose[frames == f]
            if not len(ks):
                continue
            c = before[ks, 2:4] + before[ks, 4:6] / 2
            slots, allowed = [], []
            for row in blobs:
                x0, y0, w, h = row[2:6]
                count = int(np.clip(round(areas[int(row[9])] / single), 2, 3))
                part = parts[int(row[9])]
                if np.isnan(part).any():
                    continue
                cent = part[:4].reshape(2, 2) if count == 2 else part[4:].reshape(3, 2)
                reach = math.sqrt(w * h)
                ok = np.all(np.abs(c - np.array([x0 + w / 2, y0 + h / 2])) <= np.array([w, h]) / 2 + reach, axis=1)
                slots.extend(cent)
                allowed.extend([ok] * count)
            if not slots:
                continue
            slots_a, allowed_a = np.array(slots), np.array(allowed).T
            prev = c.copy()
            for i, k in enumerate(ks):
                p = last.get(int(before[k, 1]))
                if p is not None and p[0] == f - 1:
                    prev[i] = p[1]
            cost = np.linalg.norm(c[:, None] - slots_a[None], axis=2) + np.linalg.norm(prev[:, None] - slots_a[None],
                                                                                          axis=2)
            big = 1e9
            a, b = linear_sum_assignment(np.where(allowed_a, cost, big))
            for i, j in zip(a, b):
                if not allowed_a[i, j]:
                    continue
                out[ks[i], 2:4] = slots_a[j] - out[ks[i], 4:6] / 2
                last[int(before[ks[i], 1])] = (f, slots_a[j])
        return out
    return place


N = [0]
MODES = tuple(sys.argv[2].split(",")) if len(sys.argv) > 2 else ("round4", "A", "B", "A2")


def run(video, n):
    N[0] = n
    found, parts = detections_with_parts(video)
    fps = source_frames(video)[2] or 25.0
    out = []
    areas = np.exp(found.shapes[:, 0])
    for mode in MODES:  # "shipped": the package's own (found.parts from its detector)
        closed_set.place_in_merges = place_in_merges if mode in ("round4", "shipped") else placer(parts, mode, areas)
        try:
            out.append(closed_set.track_closed_set(found.rows, n, fps, n_frames=found.frames,
                                                   online=dict(BOX_TRACKER_PARAMS), shapes=found.shapes,
                                                   parts=found.parts if mode == "shipped" else None))
        finally:
            closed_set.place_in_merges = place_in_merges
    return out


if __name__ == "__main__":
    which = sys.argv[1].split(",") if len(sys.argv) > 1 else ["arenas", "hexbug"]
    if "arenas" in which:
        scoring.summary("arenas 0-9", scoring.arenas(range(10), run, MODES, work), MODES)
    if "hexbug" in which:
        scoring.summary("hexbug", scoring.hexbug(run, MODES), MODES)
