"""Diagnosis (development arenas only, not a scoring run): how close the detector's parts of a merged blob are to the
animals inside it (run at bb6d380, before round 16 put the mixture into `blob_parts`). For every blob holding 2 or 3
reference centres, the centroids of the k-means split the detector
ships (``blob_parts``) and those of a full-covariance Gaussian mixture started from them (sklearn) are matched to the
reference centres (Hungarian); printed (cumulative over the seeds): mean distance (px) and the shares farther
than 8 and 12 px. Arguments: seeds."""
import sys
import tempfile
from pathlib import Path

import cv2
import numpy as np
from scipy.optimize import linear_sum_assignment
from sklearn.mixture import GaussianMixture

from lookalike.io.arena_files import write_arena
from lookalike.io.video_frames import source_frames
from lookalike.pipeline.blob_detections import _detector, auto_blob_config
from lookalike.vision.blob_shape import PART_COUNTS, blob_parts

work = Path(tempfile.mkdtemp(prefix="parts-gmm-"))
errors: dict[str, list[float]] = {"kmeans": [], "gmm": [], "gmm-tied": []}


def matched(centres: np.ndarray, ref: np.ndarray) -> np.ndarray:
    d = np.hypot(*(centres[:, None] - ref[None]).transpose(2, 0, 1))
    a, b = linear_sum_assignment(d)
    return d[a, b]


for seed in [int(s) for s in sys.argv[1:]] or range(10):
    files = write_arena(work / f"arena{seed}", seed=seed)
    truth = files.arena.truth
    n = len(np.unique(truth[:, 1]))
    config, _ = auto_blob_config(files.video, [], n)
    detector = _detector(files.video, config)
    count_seed = 0
    for f, image in enumerate(source_frames(files.video)[0], start=1):
        mask, _, _ = detector._foreground(image, whole=False)
        _, labels, stats, _ = cv2.connectedComponentsWithStatsWithAlgorithm(mask, 8, cv2.CV_32S, cv2.CCL_BBDT)
        pts = truth[truth[:, 0] == f][:, 2:4]
        inside = labels[np.clip(pts[:, 1].round().astype(int), 0, labels.shape[0] - 1),
                        np.clip(pts[:, 0].round().astype(int), 0, labels.shape[1] - 1)]
        for k in np.unique(inside[inside > 0]):
            ref = pts[inside == k]
            if len(ref) not in PART_COUNTS:
                continue
            ys, xs = np.nonzero(labels == k)
            vec = blob_parts(xs, ys)
            start = 0 if len(ref) == 2 else 4
            km = vec[start:start + 2 * len(ref)].reshape(-1, 2)
            xy = np.column_stack([xs, ys]).astype(float)
            errors["kmeans"] += matched(km, ref).tolist()
            for name, cov in (("gmm", "full"), ("gmm-tied", "tied")):
                g = GaussianMixture(len(ref), covariance_type=cov, means_init=km, max_iter=50, random_state=0).fit(xy)
                errors[name] += matched(g.means_, ref).tolist()
            count_seed += 1
    print(seed, count_seed, " ".join(f"{k} {np.mean(v):.2f} px >8: {np.mean(np.array(v) > 8):.3f} "
                                      f">12: {np.mean(np.array(v) > 12):.3f}" for k, v in errors.items()), flush=True)
