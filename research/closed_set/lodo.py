"""The closed set's constants by leave-one-dataset-out, as ``lodo-rule.md`` fixes it (one run; output in
``lodo-result.txt``). Run from the repository root with ../shared/data beside it::

    OMP_NUM_THREADS=1 .venv/bin/python research/closed_set/lodo.py | tee research/closed_set/lodo-result.txt
"""

from __future__ import annotations

import dataclasses
import itertools
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "benchmarks"))
from closed_points import FPS, RADIUS_PX, arena  # noqa: E402

from lookalike.bench.datasets import cut_sequence, load_boxes, load_datasets, resolve_data_root  # noqa: E402
from lookalike.bench.runner import BLOB_DATASETS, Entry, detection_rows, entry_params, score_rows, track_rows  # noqa: E402
from lookalike.eval import evaluate_points  # noqa: E402
from lookalike.io.points import POINT_VEL_NOISE, points_to_rows, rows_to_points  # noqa: E402
from lookalike.trackers.offline.closed_set import ClosedSetConfig, assign_identities, online_rows  # noqa: E402
from lookalike.vision.blob_auto import BOX_TRACKER_PARAMS  # noqa: E402

ONLINE = Entry("boxtrack-closed", "boxtrack", closed_set=True)
DEFAULT = (3.0, 3.0, 1.0)
GRID = list(itertools.product([1.0, 3.0, 10.0], [0.0, 3.0, 10.0], [0.0, 1.0]))  # tracklet_cost, edge_cost, smooth_s


@dataclasses.dataclass
class Case:
    group: str
    name: str
    n: int
    fps: float
    first_pass: np.ndarray  # the online n_init=1 pass the offline assignment starts from
    score: Any  # rows -> metrics
    online: dict[str, float]  # the online closed set's metrics


def _points_score(gt: np.ndarray, length: int) -> Any:
    def score(rows: np.ndarray) -> dict[str, float]:
        f, i, xy = rows_to_points(rows)
        return evaluate_points(gt[:, 0].astype(int), gt[:, 1].astype(int), gt[:, 2:4], f, i, xy, radius=RADIUS_PX,
                               num_frames=length)
    return score


def cases() -> list[Case]:
    root = resolve_data_root(None)
    out = []
    pigs = load_boxes(root / "pigs", "pigs")[0]
    seqs = [("pigs", f"pigs-{part}", cut_sequence(pigs, part)) for part in ("first", "second")]
    for seq in load_datasets(root, ["hexbug"]):
        seqs.append(("hexbug", seq.name, dataclasses.replace(seq, n_targets=len(np.unique(seq.gt_points[1])))))
    for group, name, seq in seqs:
        online = {k: v for k, v in entry_params(ONLINE, seq).items() if k != "max_targets"}
        if seq.dataset in BLOB_DATASETS:
            online = {**BOX_TRACKER_PARAMS, **online}
        first = online_rows(detection_rows(seq), seq.frame_rate, seq.length, **{"n_init": 1, **online})
        out.append(Case(group, name, seq.n_targets, seq.frame_rate,
                        first, lambda rows, seq=seq: score_rows(seq, rows), score_rows(seq, track_rows(ONLINE, seq))))
    from lookalike.loop import RowCollector, run
    from lookalike.trackers.boxtrack import BoxTrack, BoxTrackConfig
    from lookalike.types import Detections, Frame

    for n in (3, 5, 8):
        for seed in range(100, 105):
            pf, gt = arena(n=n, seed=seed)
            det = points_to_rows(pf)
            score = _points_score(gt, len(pf))
            collect = RowCollector()
            run(BoxTrack(BoxTrackConfig(max_targets=n), vel_noise=POINT_VEL_NOISE),
                (Frame(index=k, time=k / FPS, detections=Detections(xywh=det[det[:, 0] == k + 1, 2:6],
                                                                     score=det[det[:, 0] == k + 1, 6]))
                 for k in range(len(pf))), collect)
            first = online_rows(det, FPS, len(pf), n_init=1, vel_noise=POINT_VEL_NOISE)
            out.append(Case("arenas", f"arena{n}-{seed}", n, FPS, first, score, score(collect.rows())))
    return out


def value(s: dict[str, float]) -> float:
    return 100 * (s["IDF1"] + s["HOTA"])


def main() -> None:
    t0 = time.process_time()
    data = cases()
    groups = sorted({c.group for c in data})
    print(f"{len(data)} sequences ({', '.join(f'{g}: {sum(c.group == g for c in data)}' for g in groups)}), "
          f"{len(GRID)} candidates (tracklet_cost, edge_cost, smooth_s)", flush=True)
    table: dict[tuple[float, ...], dict[str, float]] = {}  # candidate -> sequence -> IDF1 + HOTA
    for cand in GRID:
        cfg = ClosedSetConfig(tracklet_cost=cand[0], edge_cost=cand[1], smooth_s=cand[2])
        table[cand] = {c.name: value(c.score(assign_identities(c.first_pass, c.n, c.fps, cfg))) for c in data}
        print(f"  {cand}: " + "  ".join(
            f"{g} {np.mean([table[cand][c.name] for c in data if c.group == g]):.2f}" for g in groups), flush=True)
    online = {c.name: value(c.online) for c in data}

    def group_score(scores: dict[str, float], g: str) -> float:
        return float(np.mean([scores[c.name] for c in data if c.group == g]))

    def choose(train: list[str]) -> tuple[float, ...]:
        best = max(GRID, key=lambda cand: (round(np.mean([group_score(table[cand], g) for g in train]), 9),
                                           cand == DEFAULT))
        return best

    print("\nleft out | chosen on the others | IDF1+HOTA left out: chosen / shipped defaults / online --targets N")
    folds_ok = []
    for g in groups:
        cand = choose([h for h in groups if h != g])
        got, default, on = group_score(table[cand], g), group_score(table[DEFAULT], g), group_score(online, g)
        folds_ok.append(got >= default)
        print(f"{g:8s} | {cand} | {got:.2f} / {default:.2f} / {on:.2f}   offline >= online: {got >= on}")
        if g == "pigs":
            for c in data:
                if c.group == "pigs":
                    cfg = ClosedSetConfig(tracklet_cost=cand[0], edge_cost=cand[1], smooth_s=cand[2])
                    s = c.score(assign_identities(c.first_pass, c.n, c.fps, cfg))
                    print(f"         {c.name}: IDF1 {100 * s['IDF1']:.2f} HOTA {100 * s['HOTA']:.2f} "
                          f"(online --targets 23: IDF1 {100 * c.online['IDF1']:.2f} HOTA {100 * c.online['HOTA']:.2f})")
    on_all = choose(groups)
    ship = on_all if all(folds_ok) else DEFAULT
    print(f"\nchosen on all three groups: {on_all}; every fold at least the defaults: {all(folds_ok)}; "
          f"ship: {ship}  ({time.process_time() - t0:.0f} s CPU)")


if __name__ == "__main__":
    main()
