"""Corrections per point of IDF1: a simulated proofreader that knows the ground truth corrects a closed-set result
with :class:`lookalike.proofread.Session`, once with corrections that re-solve the closed set (propagation) and once
as plain edits (what peers' proofreading tools do), from the same starting result.

The proofreader (rule fixed before any scoring): it goes to the most doubtful range of the current result
(:meth:`Session.doubtful`), looks at its frames widened by one second each side, and makes the one correction the
earliest identity error there needs; a range with no error is marked looked. With no range left it goes to the first
error in time. Each result id stands for the truth identity it covers most often (as IDF1 maps them; a row covers a
truth identity it matches in its frame: boxes IoU >= 0.5, points within the scoring radius; its own when it covers
it). An error is where the identity an id covers changes from ``a`` to ``b`` at frame ``k`` and one side is not its own
(a switch), or where an id starts on an identity another id covered before (a fragment, ``a`` none). Its correction:
swap the id from ``k`` on with the id that next covers ``a`` (an assign when the two share no frame from ``k`` on); else
with the id that last covered ``b`` before ``k``; else split at ``k``. Corrections that fail or were made before (a
swap of ``i`` with ``j`` is one of ``j`` with ``i``) are skipped and not counted; a correction that lowers IDF1 is taken
back (undo) but counted.

Data: the pig dev video with ``--targets 23`` (the closed set's rules were refined on this video: issue 43),
simulated 5-animal point arenas (``closed_points.arena``, seeds 200-219, never used for any choice; the proofreader's
mechanics were debugged on seeds 0-9) and the 14 annotated HexBug clips through the blob detector with ``--targets N``
(N: the clip's annotated count; each bug's look learned from the clip weighs in the start and every re-solve, as
``track --targets N`` on a blob video does since the look became its default); and 8-animal hard arenas (``HARD``:
faster, 10% missed, 0.3 false points a frame; seeds 300-307, eight for time: re-solves there took minutes before the
flow encoding of corrections), added after the first run with the rule unchanged, to see propagation where errors are
many. Run::

    python benchmarks/proofread_curve.py [--data ../shared/data] [--seeds 200-219] [--plot docs/images/proofread.png]
"""

from __future__ import annotations

import argparse
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from closed_pigs import det_rows
from closed_points import FPS, RADIUS_PX, arena, seeds_of
from scipy.optimize import linear_sum_assignment

from lookalike.bench.datasets import detect_hexbug, hexbug_clips, load_boxes, resolve_data_root
from lookalike.bench.runner import HEXBUG_RADIUS_PX, score_rows
from lookalike.eval import evaluate_points
from lookalike.geometry.boxes import iou_matrix
from lookalike.io.points import POINT_VEL_NOISE, points_to_rows, rows_to_points
from lookalike.proofread import Correction, Session
from lookalike.trackers.offline.closed_set import assign_identities, online_rows

STEPS = (0, 1, 2, 5, 10, 20)


@dataclass
class Case:
    """One sequence: start rows, the closed set's input rows, and its truth (per frame ids and geometry)."""

    name: str
    rows: np.ndarray
    solver_input: np.ndarray
    n_targets: int
    frame_rate: float
    gt_frame: np.ndarray
    gt_id: np.ndarray
    gt_geom: np.ndarray  # (n, 4) boxes px or (n, 2) points px
    score: Callable[[np.ndarray], float]
    radius: float = RADIUS_PX  # points: a row's box centre matches within this (px)
    shapes: np.ndarray | None = None  # blob shape vectors that column 9 of solver_input indexes (the learned look)
    parts: np.ndarray | None = None  # the blobs' parts vectors, indexed as shapes


def judge(rows: np.ndarray, case: Case) -> tuple[np.ndarray, np.ndarray, dict[int, int]]:
    """Per row whether its id is right and the truth id it covers (-1: none), and the truth id of each result id.

    A row covers a truth identity when they match in its frame (boxes IoU >= 0.5, points within the scoring radius);
    each result id stands for the truth identity it covers most often (one-to-one, as IDF1 maps them); a row is right
    when it covers its id's identity. Rows that cover no identity are neither right nor wrong."""
    pairs = []
    for f in np.unique(rows[:, 0]):
        r = np.flatnonzero(rows[:, 0] == f)
        g = np.flatnonzero(case.gt_frame == f)
        if not len(g):
            continue
        if case.gt_geom.shape[1] == 4:
            sim = iou_matrix(rows[r, 2:6], case.gt_geom[g])
            ok = sim >= 0.5
        else:
            d = np.linalg.norm((rows[r, 2:4] + rows[r, 4:6] / 2)[:, None] - case.gt_geom[g][None], axis=2)
            sim, ok = -d, d <= case.radius
        for x, y in zip(*np.nonzero(ok)):
            pairs.append((r[x], case.gt_id[g[y]], sim[x, y]))
    ids, gts = np.unique(rows[:, 1]).astype(int), np.unique(case.gt_id)
    count = np.zeros((len(ids), len(gts)))
    if pairs:
        p = np.array(pairs)
        np.add.at(count, (np.searchsorted(ids, rows[p[:, 0].astype(int), 1]), np.searchsorted(gts, p[:, 1])), 1)
    a, b = linear_sum_assignment(-count)
    stands = {int(ids[x]): int(gts[y]) for x, y in zip(a, b) if count[x, y] > 0}
    right = np.zeros(len(rows), bool)
    cover = np.full(len(rows), -1)
    best = np.full(len(rows), -np.inf)
    for row, truth, v in pairs:
        k, t = int(row), int(truth)
        right[k] |= stands.get(int(rows[k, 1])) == t
        if v > best[k]:
            best[k], cover[k] = v, t
    cover[right] = [stands[int(i)] for i in rows[right, 1]]
    return right, cover, stands


def errors(rows: np.ndarray, right: np.ndarray, cover: np.ndarray) -> list[tuple[int, int, int, int]]:
    """``(frame, id, truth before, truth now)`` where an id's covered truth identity changes between two of its
    covering rows and one side is wrong (a switch), or ``(frame, id, -1, truth)`` where an id starts on an identity
    another id covered before (a fragment); by frame."""
    idx = np.flatnonzero(cover >= 0)
    idx = idx[np.lexsort((rows[idx, 0], rows[idx, 1]))]
    r, c, ok = rows[idx], cover[idx], right[idx]
    new_id = np.r_[True, r[1:, 1] != r[:-1, 1]]
    switch = ~new_id & np.r_[False, c[1:] != c[:-1]] & ~(ok & np.r_[True, ok[:-1]])
    out = [(int(r[k, 0]), int(r[k, 1]), int(c[k - 1]), int(c[k])) for k in np.flatnonzero(switch)]
    for k in np.flatnonzero(new_id):
        if ((c == c[k]) & (r[:, 0] < r[k, 0]) & (r[:, 1] != r[k, 1])).any():
            out.append((int(r[k, 0]), int(r[k, 1]), -1, int(c[k])))
    out.sort()
    return out


def correction_for(err: tuple[int, int, int, int], rows: np.ndarray, cover: np.ndarray) -> Correction | None:
    """The one correction an error needs (module doc); None when there is none to make."""
    f, i, a, b = err
    later, before, other = rows[:, 0] >= f, rows[:, 0] < f, rows[:, 1] != i
    mine = rows[(rows[:, 1] == i) & later, 0]
    if a >= 0:
        holder = rows[later & other & (cover == a)]
        if len(holder):
            j = int(holder[np.argmin(holder[:, 0]), 1])
            clash = np.isin(mine, rows[(rows[:, 1] == j) & later, 0]).any()
            return Correction("swap" if clash else "assign", i, j, f)
    prev = rows[before & other & (cover == b)]
    if len(prev):
        j = int(prev[np.argmax(prev[:, 0]), 1])
        clash = np.isin(mine, rows[(rows[:, 1] == j) & later, 0]).any()
        return Correction("swap" if clash else "assign", i, j, f)
    return Correction("split", i, frame=f) if a >= 0 else None


def _key(c: Correction) -> object:
    """A correction as tried: a swap of i with j is the swap of j with i."""
    return (c.kind, frozenset((c.track, c.other)), c.frame) if c.kind == "swap" else c


def proofread(case: Case, propagate: bool, max_corrections: int = STEPS[-1]) -> list[float]:
    """IDF1 (%) after 0..``max_corrections`` corrections (the last value repeated once nothing is left to correct)."""
    s = Session(case.rows, frame_rate=case.frame_rate, n_targets=case.n_targets if propagate else None,
                solver_input=case.solver_input if propagate else None, shapes=case.shapes if propagate else None,
                parts=case.parts if propagate else None)
    curve = [100 * case.score(s.rows)]
    tried: set[object] = set()
    looked: set[tuple[int, int, int]] = set()
    w = max(1, round(case.frame_rate))
    for _ in range(50 * max_corrections):
        if len(curve) > max_corrections:
            break
        right, cover, stands = judge(s.rows, case)
        found = [(e, correction_for(e, s.rows, cover)) for e in errors(s.rows, right, cover)]
        fixes = [(e, c) for e, c in found if c is not None and _key(c) not in tried]
        if not fixes:
            break
        pick = None
        for d in s.doubtful():
            if (d.track, d.first, d.last) in looked:
                continue
            inside = [(e, c) for e, c in fixes if d.first - w <= e[0] <= d.last + w]
            if inside:
                pick = inside[0][1]
                break
            looked.add((d.track, d.first, d.last))
        c = pick or fixes[0][1]
        tried.add(_key(c))
        try:
            s.apply(c)
        except ValueError:
            continue
        curve.append(100 * case.score(s.rows))
        if curve[-1] < curve[-2]:  # it looks at the result: worse, so it takes the correction back (still counted)
            s.undo()
            curve[-1] = curve[-2]
    return curve + [curve[-1]] * (max_corrections + 1 - len(curve))


def pig_case(root: object) -> Case:
    seq = load_boxes(root / "pigs", "pigs")[0]  # type: ignore[operator]
    on = online_rows(det_rows(seq), seq.frame_rate, seq.length, n_init=1)
    rows = assign_identities(on, 23, seq.frame_rate)
    gt = seq.gt
    assert gt is not None
    keep = gt.conf > 0
    return Case("pigs", rows, on, 23, seq.frame_rate, gt.frame[keep], gt.track_id[keep], gt.xywh[keep],
                lambda r: float(score_rows(seq, r)["IDF1"]))


HARD = {"n": 8, "speed": 4.5, "miss": 0.10, "clutter": 0.3}  # denser, faster, more misses and false points


def arena_case(seed: int, n: int = 5, **kwargs: float) -> Case:
    pf, gt = arena(n=n, seed=seed, **kwargs)  # type: ignore[arg-type]
    on = online_rows(points_to_rows(pf), FPS, len(pf), n_init=1, vel_noise=POINT_VEL_NOISE)
    rows = assign_identities(on, n, FPS)

    def score(r: np.ndarray) -> float:
        f, i, xy = rows_to_points(r)
        return float(evaluate_points(gt[:, 0].astype(int), gt[:, 1].astype(int), gt[:, 2:4], f, i, xy,
                                     radius=RADIUS_PX, num_frames=len(pf))["IDF1"])

    return Case(f"arena {seed}", rows, on, n, FPS, gt[:, 0].astype(int), gt[:, 1].astype(int), gt[:, 2:4], score)


def hexbug_cases(root: Path) -> list[Case]:
    """The HexBug clips with annotations, through the blob detector (``--detector blob``) and the closed set of the
    clip's annotated count with the look learned from the clip (``--targets N``, the default on a blob video)."""
    from lookalike.pipeline.blob_detections import auto_blob_config, cached_blob_detections

    out = []
    for video in hexbug_clips(root / "hexbug"):
        seq = detect_hexbug(video)
        assert seq.gt_points is not None
        frame, ids, xy = seq.gt_points
        n = len(np.unique(ids))
        found = cached_blob_detections(video, auto_blob_config(video, [])[0])  # (detect_hexbug's, from the cache)
        on = online_rows(found.rows, seq.frame_rate, seq.length, n_init=1, index=True)
        rows = assign_identities(on, n, seq.frame_rate, shapes=found.shapes, parts=found.parts)
        out.append(Case(f"hexbug {seq.name}", rows, on, n, seq.frame_rate, frame, ids, xy,
                        lambda r, seq=seq: float(score_rows(seq, r)["IDF1"]), HEXBUG_RADIUS_PX,  # type: ignore[misc]
                        found.shapes, found.parts))
    return out


def oracle(case: Case) -> float:
    """IDF1 (%) of the start rows with every row that covers an identity on the id standing for it (each result id
    stands for one identity, as IDF1 maps them; rows of an identity no id stands for get a new id): about what
    identity corrections alone can reach (not a strict bound: the corrected rows may map differently)."""
    right, cover, stands = judge(case.rows, case)
    inv = {g: i for i, g in stands.items()}
    rows = case.rows.copy()
    spare = int(rows[:, 1].max()) + 1
    for g in np.unique(cover[cover >= 0]):
        inv.setdefault(int(g), spare + int(g))
    wrong = ~right & (cover >= 0)
    rows[wrong, 1] = [inv[int(g)] for g in cover[wrong]]
    held = {(f, i) for f, i in rows[~wrong, :2].astype(int).tolist()}
    fresh = int(rows[:, 1].max()) + 1
    for k in np.flatnonzero(wrong):  # a relabelled row whose id already has a row in its frame gets a new id
        key = (int(rows[k, 0]), int(rows[k, 1]))
        if key in held:
            rows[k, 1], fresh = fresh, fresh + 1
            key = (key[0], int(rows[k, 1]))
        held.add(key)
    return 100 * case.score(rows)


def first_reaching(curve: list[float], target: float) -> str:
    hit = [k for k, v in enumerate(curve) if v >= target - 1e-9]
    return str(hit[0]) if hit else f"> {len(curve) - 1}"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n", 1)[0])
    ap.add_argument("--data", default=None)
    ap.add_argument("--seeds", default="200-219", help="arena seeds A-B (200-219: never used for a choice)")
    ap.add_argument("--hard-seeds", default="300-307", help="seeds of the hard arenas (HARD; never used for a choice)")
    ap.add_argument("--plot", default=None, help="write the curves as a PNG here")
    ap.add_argument("--no-hexbug", action="store_true", help="leave out the HexBug clips (their blob detection)")
    args = ap.parse_args()
    t0 = time.process_time()
    root = resolve_data_root(args.data)
    modes = ("propagation", "plain edits")
    groups = {"pigs, --targets 23": [pig_case(root)],
              f"5-animal arenas (seeds {args.seeds})": [arena_case(seed) for seed in seeds_of(args.seeds)],
              f"8-animal hard arenas (seeds {args.hard_seeds})": [arena_case(seed, **HARD)  # type: ignore[arg-type]
                                                                  for seed in seeds_of(args.hard_seeds)]}
    if not args.no_hexbug:
        groups["HexBug clips, --targets N"] = hexbug_cases(root)
    goals = {"pigs, --targets 23": 98.0}
    runs: dict[str, dict[str, list[list[float]]]] = {}
    for name, cases in groups.items():
        runs[name] = {m: [] for m in modes}
        for case in cases:
            for m in modes:
                t1 = time.perf_counter()
                runs[name][m].append(proofread(case, m == "propagation"))
                print(f"  {case.name:<22} {m:<12}" + "".join(f"{runs[name][m][-1][k]:8.2f}" for k in STEPS)
                      + f"  ({time.perf_counter() - t1:.0f} s)", flush=True)
    curves = {name: {m: list(np.mean(v, axis=0)) for m, v in per.items()} for name, per in runs.items()}
    tops = {name: float(np.mean([oracle(c) for c in cases])) for name, cases in groups.items()}
    print("IDF1 (%, mean over sequences) after N corrections; oracle: every covering row of the start on its "
          f"identity's id\n"
          f"{'data':<36} {'N':<12}" + "".join(f"{k:>8d}" for k in STEPS) + f"{'oracle':>9}")
    for name, per_mode in curves.items():
        for m, c in per_mode.items():
            print(f"{name:<36} {m:<12}" + "".join(f"{c[k]:8.2f}" for k in STEPS) + f"{tops[name]:9.2f}")
    for name, per in runs.items():
        goal = goals.get(name, 99.5)
        for m, v in per.items():
            reach = [first_reaching(c, goal) for c in v]
            print(f"{name}, {m}: corrections to IDF1 >= {goal}: mean curve {first_reaching(curves[name][m], goal)}; "
                  f"per sequence {' '.join(reach)}; sequences reaching it within 5: "
                  f"{sum(max(c[:6]) >= goal for c in v)} of {len(v)}, within 20: {sum(max(c) >= goal for c in v)}")
    print(f"({time.process_time() - t0:.0f} s CPU)")
    if args.plot:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        fig, axes = plt.subplots(1, len(curves), figsize=(4.2 * len(curves), 3.6))
        for ax, (name, per_mode) in zip(np.atleast_1d(axes), curves.items()):
            for m, c in per_mode.items():
                ax.plot(range(len(c)), c, marker="o", ms=3, label=m)
            ax.axhline(tops[name], ls="--", lw=1, color="grey", label="oracle relabelling of the start")
            ax.set_title(f"{name} (mean of {len(groups[name])})" if len(groups[name]) > 1 else name, fontsize=9)
            ax.set_xlabel("corrections")
            ax.set_ylabel("IDF1 (%)")
            ax.grid(alpha=0.3)
            ax.legend(fontsize=8)
        fig.tight_layout()
        fig.savefig(args.plot, dpi=110)
        print(f"plot: {args.plot}")


if __name__ == "__main__":
    main()
