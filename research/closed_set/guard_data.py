"""Online closed set (``track --targets N``) against the offline one (``--targets N --offline``) on every closed-set
sequence with ground truth: the pig video's halves, the HexBug clips, simulated point arenas. Prints one JSON line per
sequence with both results' IDF1/HOTA and the label-free signals a fallback rule could use. Run from the repository
root: ``python research/closed_set/guard_data.py > research/closed_set/guard_data.jsonl``."""

from __future__ import annotations

import dataclasses
import json
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "benchmarks"))
from closed_points import FPS, RADIUS_PX, arena  # noqa: E402

from lookalike.bench.datasets import cut_sequence, load_boxes, load_datasets, resolve_data_root  # noqa: E402
from lookalike.bench.runner import Entry, score_rows, track_rows  # noqa: E402
from lookalike.eval import evaluate_points  # noqa: E402
from lookalike.geometry.boxes import iou_matrix  # noqa: E402
from lookalike.io.points import POINT_VEL_NOISE, points_to_rows, rows_to_points  # noqa: E402
from lookalike.loop import RowCollector, run  # noqa: E402
from lookalike.trackers.boxtrack import BoxTrack, BoxTrackConfig  # noqa: E402
from lookalike.trackers.offline.closed_set import track_closed_set  # noqa: E402
from lookalike.types import Detections, Frame  # noqa: E402

ONLINE = Entry("boxtrack-closed", "boxtrack", closed_set=True)
OFFLINE = Entry("boxtrack-closed-offline", "boxtrack", closed_set=True, closed_offline=True)


def signals(on: np.ndarray, off: np.ndarray) -> dict[str, float]:
    """Agreement of the two results' identities on the boxes they share (IoU >= 0.5 in a frame), and the share of
    the online rows the offline result keeps."""
    pairs = []
    for f in np.intersect1d(on[:, 0], off[:, 0]):
        a, b = on[on[:, 0] == f], off[off[:, 0] == f]
        iou = iou_matrix(a[:, 2:6], b[:, 2:6])
        i, j = np.nonzero(iou >= 0.5)
        pairs += list(zip(a[i, 1].astype(int), b[j, 1].astype(int)))
    if not pairs:
        return {"agree": 0.0, "kept": 0.0}
    p = np.array(pairs)
    agree = sum(np.bincount(np.unique(p[p[:, 0] == u, 1], return_inverse=True)[1]).max() for u in np.unique(p[:, 0]))
    return {"agree": agree / len(p), "kept": len(p) / len(on)}


def _line(name: str, group: str, n: int, on: np.ndarray, off: np.ndarray, s_on: dict, s_off: dict) -> None:
    print(json.dumps({"name": name, "group": group, "n": n, "on_idf1": s_on["IDF1"], "off_idf1": s_off["IDF1"],
                      "on_hota": s_on["HOTA"], "off_hota": s_off["HOTA"], **signals(on, off)}), flush=True)


def main(groups: tuple[str, ...] = ("pigs", "hexbug", "arenas")) -> None:
    root = resolve_data_root(None)
    if "pigs" in groups:
        _pigs(root)
    if "hexbug" in groups:
        _hexbug(root)
    if "arenas" in groups:
        _arenas()


def _pigs(root: Path) -> None:
    pigs = load_boxes(root / "pigs", "pigs")[0]
    for part in ("first", "second"):
        seq = cut_sequence(pigs, part)
        on, off = track_rows(ONLINE, seq), track_rows(OFFLINE, seq)
        _line(f"pigs-{part}", "pigs", 23, on, off, score_rows(seq, on), score_rows(seq, off))


def _hexbug(root: Path) -> None:
    for seq in load_datasets(root, ["hexbug"]):
        n = len(np.unique(seq.gt_points[1]))  # the clip's annotated bugs: what a user passes as --targets
        seq = dataclasses.replace(seq, n_targets=n)
        on, off = track_rows(ONLINE, seq), track_rows(OFFLINE, seq)
        _line(seq.name, "hexbug", n, on, off, score_rows(seq, on), score_rows(seq, off))


def _arenas() -> None:
    for n in (3, 5, 8):
        for seed in range(100, 105):
            pf, gt = arena(n=n, seed=seed)
            det = points_to_rows(pf)
            tracker = BoxTrack(BoxTrackConfig(max_targets=n), vel_noise=POINT_VEL_NOISE)
            collect = RowCollector()
            frames = (Frame(index=k, time=k / FPS, detections=Detections(xywh=det[det[:, 0] == k + 1, 2:6],
                                                                         score=det[det[:, 0] == k + 1, 6]))
                      for k in range(len(pf)))
            run(tracker, frames, collect)
            on = collect.rows()
            off = track_closed_set(det, n, FPS, n_frames=len(pf), vel_noise=POINT_VEL_NOISE)
            scores = []
            for rows in (on, off):
                f, i, xy = rows_to_points(rows)
                scores.append(evaluate_points(gt[:, 0].astype(int), gt[:, 1].astype(int), gt[:, 2:4], f, i, xy,
                                              radius=RADIUS_PX, num_frames=len(pf)))
            _line(f"arena{n}-{seed}", f"arena{n}", n, on, off, *scores)


if __name__ == "__main__":
    main(tuple(sys.argv[1:]) or ("pigs", "hexbug", "arenas"))
