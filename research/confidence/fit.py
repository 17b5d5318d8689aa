"""Per-row identity confidence: leave-one-dataset-out calibration and the shipped coefficients, as ``rule.md``
fixes them (one run; output in ``fit-result.txt``, diagram in ``docs/images/confidence-reliability.png``). Run from
the repository root with ../shared/data beside it::

    OMP_NUM_THREADS=1 .venv/bin/python research/confidence/fit.py | tee research/confidence/fit-result.txt
"""

from __future__ import annotations

import dataclasses
import sys
import time
from pathlib import Path

import numpy as np

from lookalike.bench.datasets import load_datasets, resolve_data_root
from lookalike.bench.runner import HEXBUG_RADIUS_PX, Entry, score_rows, track_rows
from lookalike.eval import box_iou, point_similarity
from lookalike.eval.matching import hungarian
from lookalike.trackers.offline.confidence import FEATURES, doubtful_ranges, logistic, row_features

DATASETS = ("mot15", "pigs", "mot17-synth", "hexbug")
ONLINE = Entry("boxtrack", "boxtrack")
CLOSED = Entry("boxtrack-closed-offline", "boxtrack", closed_set=True, closed_offline=True)
THRESHOLD, EXPLORE = 0.5, (0.3, 0.7, 0.9)
PENALTY, STEPS, BINS = 1.0, 50, 10
EPS = np.finfo(float).eps
ROOT = Path(__file__).resolve().parents[2]


@dataclasses.dataclass
class Result:
    """One tracker result on one sequence: rows, features, labels (1 right, 0 wrong, -1 left out), switches."""

    dataset: str
    kind: str
    name: str
    fps: float
    rows: np.ndarray
    features: np.ndarray
    label: np.ndarray
    switches: list[tuple[int, int, int, int]]  # (old id, its last frame, new id, frame)
    idp_eval: float


def ground_truth(seq: object) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, bool]:
    """(frame, id, xywh or xy, kept by the benchmark's rules, is_points) of a sequence's ground truth."""
    if seq.gt is not None:  # type: ignore[attr-defined]
        gt = seq.gt  # type: ignore[attr-defined]
        keep = gt.conf != 0
        if seq.benchmark == "MOT17":  # type: ignore[attr-defined]
            keep &= gt.extra[:, 0].astype(int) == 1
        return gt.frame.astype(int), gt.track_id.astype(int), gt.xywh, keep, False
    frame, ids, xy = seq.gt_points  # type: ignore[attr-defined]
    return frame.astype(int), ids.astype(int), xy, np.ones(len(frame), bool), True


def label_rows(seq: object, rows: np.ndarray,
               radius: float = HEXBUG_RADIUS_PX) -> tuple[np.ndarray, list[tuple[int, int, int, int]]]:
    """Per-row labels under the global IDF1 mapping and CLEAR's identity switches (rule.md); ``radius`` px for
    ground-truth points."""
    g_frame, g_id, g_pos, g_keep, points = ground_truth(seq)
    length = seq.length  # type: ignore[attr-defined]
    inside = g_frame <= length
    g_frame, g_id, g_pos, g_keep = g_frame[inside], g_id[inside], g_pos[inside], g_keep[inside]
    r_frame, r_id = rows[:, 0].astype(int), rows[:, 1].astype(int)
    r_pos = rows[:, 2:4] + rows[:, 4:6] / 2 if points else rows[:, 2:6]
    gt_ids, g_rel = np.unique(g_id[g_keep], return_inverse=True)
    tr_ids, t_rel = np.unique(r_id, return_inverse=True)
    g_rel_all = np.full(len(g_id), -1)
    g_rel_all[g_keep] = g_rel

    def sim(a: np.ndarray, b: np.ndarray) -> np.ndarray:
        return point_similarity(a, b, radius) if points else box_iou(a, b)

    g_order, r_order = np.argsort(g_frame, kind="stable"), np.argsort(r_frame, kind="stable")
    g_b = np.searchsorted(g_frame[g_order], np.arange(1, length + 2))
    r_b = np.searchsorted(r_frame[r_order], np.arange(1, length + 2))
    pair_row, pair_gt = [], []  # strong pairs: row index, relabelled gt id
    dropped_match = np.zeros(len(rows), bool)
    frames_pairs = []
    for t in range(length):
        g = g_order[g_b[t]:g_b[t + 1]]
        r = r_order[r_b[t]:r_b[t + 1]]
        if not len(g) or not len(r):
            frames_pairs.append((g[:0], r[:0], np.zeros((0, 0))))
            continue
        s = sim(g_pos[g], r_pos[r])
        strong = s >= 0.5 - EPS
        kept = g_keep[g]
        dropped_match[r[(strong & ~kept[:, None]).any(axis=0)]] = True
        gk = g[kept]
        sk = s[kept]
        i, j = np.nonzero(sk >= 0.5 - EPS)
        pair_row.append(r[j])
        pair_gt.append(g_rel_all[gk[i]])
        frames_pairs.append((gk, r, sk))
    p_row = np.concatenate(pair_row) if pair_row else np.zeros(0, int)
    p_gt = np.concatenate(pair_gt) if pair_gt else np.zeros(0, int)
    overlap = np.zeros((len(gt_ids), len(tr_ids)))
    np.add.at(overlap, (p_gt, t_rel[p_row]), 1)
    solve = hungarian()
    mapped = np.full(len(tr_ids), -1)
    if overlap.size:
        a, b = solve(overlap, maximize=True)
        mapped[b] = a
    label = np.zeros(len(rows), int)
    label[p_row[mapped[t_rel[p_row]] == p_gt]] = 1
    label[(label == 0) & dropped_match] = -1
    # CLEAR switches over the labelled rows.
    last_id = np.full(len(gt_ids), -1)
    last_frame = np.zeros(len(gt_ids), int)
    switches = []
    for t, (gk, r, sk) in enumerate(frames_pairs):
        if not len(gk) or not len(r):
            continue
        use = label[r] >= 0
        r, sk = r[use], sk[:, use]
        if not len(r):
            continue
        gr = g_rel_all[gk]
        ok = sk >= 0.5 - EPS
        score = np.where(ok, sk, 0.0) + 1000.0 * (ok & (last_id[gr][:, None] == r_id[r][None, :]))
        a, b = solve(score, maximize=True)
        m = ok[a, b]
        for gi, ri in zip(gr[a[m]].tolist(), r[b[m]].tolist()):
            new = int(r_id[ri])
            if last_id[gi] >= 0 and last_id[gi] != new:
                switches.append((int(last_id[gi]), int(last_frame[gi]), new, t + 1))
            last_id[gi], last_frame[gi] = new, t + 1
    return label, switches


def results() -> list[Result]:
    root = resolve_data_root(ROOT.parent / "shared" / "data")
    out = []
    for name in DATASETS:
        for seq in load_datasets(root, [name]):
            if seq.dataset == "hexbug":
                seq = dataclasses.replace(seq, n_targets=len(np.unique(seq.gt_points[1])))
            entries = [("online", ONLINE)] + ([("closed-offline", CLOSED)] if seq.n_targets else [])
            for kind, entry in entries:
                rows = track_rows(entry, seq)
                label, switches = label_rows(seq, rows)
                idp = score_rows(seq, rows)["IDP"]
                out.append(Result(name, kind, seq.name, seq.frame_rate, rows, row_features(rows, seq.frame_rate),
                                  label, switches, idp))
                mine = label[label >= 0].mean() if (label >= 0).any() else float("nan")
                print(f"  {name:11s} {seq.name:22s} {kind:14s} rows {len(rows):6d} right {mine:.3f} "
                      f"(IDP {idp:.3f}) left out {int((label < 0).sum())} switches {len(switches)}", flush=True)
    return out


def fit(x: np.ndarray, y: np.ndarray, w: np.ndarray) -> np.ndarray:
    """Weighted L2-penalised logistic regression (rule.md), coefficients on raw features: intercept first."""
    mu = np.average(x, axis=0, weights=w)
    sd = np.sqrt(np.average((x - mu) ** 2, axis=0, weights=w))
    sd[sd < 1e-12] = 1.0
    z = np.column_stack([np.ones(len(x)), (x - mu) / sd])
    beta = np.zeros(z.shape[1])
    pen = np.full(z.shape[1], PENALTY)
    pen[0] = 0.0
    for _ in range(STEPS):
        p = 1.0 / (1.0 + np.exp(-np.clip(z @ beta, -50, 50)))
        grad = z.T @ (w * (p - y)) + pen * beta
        hess = (z * (w * p * (1 - p))[:, None]).T @ z + np.diag(pen)
        step = np.linalg.solve(hess, grad)
        beta -= step
        if np.abs(step).max() < 1e-10:
            break
    raw = beta[1:] / sd
    return np.r_[beta[0] - raw @ mu, raw]


def ece(p: np.ndarray, y: np.ndarray) -> tuple[float, np.ndarray, np.ndarray, np.ndarray]:
    """ECE over 10 equal-width bins, and per bin (mean probability, share right, rows)."""
    b = np.minimum((p * BINS).astype(int), BINS - 1)
    n = np.bincount(b, minlength=BINS).astype(float)
    mp = np.bincount(b, p, BINS) / np.maximum(n, 1)
    my = np.bincount(b, y, BINS) / np.maximum(n, 1)
    return float(np.sum(n / max(len(p), 1) * np.abs(mp - my))), mp, my, n


def auc(p: np.ndarray, y: np.ndarray) -> float:
    from scipy.stats import rankdata

    pos, neg = int(y.sum()), int(len(y) - y.sum())
    if not pos or not neg:
        return float("nan")
    return float((rankdata(p)[y == 1].sum() - pos * (pos + 1) / 2) / (pos * neg))


def switch_share(rs: list[Result], probs: list[np.ndarray], threshold: float) -> tuple[int, int, float]:
    """(switches inside a range, switches, share of rows inside a range)."""
    inside = total = rows_in = rows_all = 0
    for r, p in zip(rs, probs):
        ranges = doubtful_ranges(r.rows, p, r.fps, threshold)

        def covered(i: int, f: int, ranges: dict[int, list[tuple[int, int]]] = ranges) -> bool:
            return any(a <= f <= b for a, b in ranges.get(i, []))

        for old, f_old, new, f in r.switches:
            total += 1
            inside += covered(new, f) or covered(old, f_old)
        for i, spans in ranges.items():
            sel = r.rows[r.rows[:, 1] == i, 0]
            rows_in += sum(int(((sel >= a) & (sel <= b)).sum()) for a, b in spans)
        rows_all += len(r.rows)
    return inside, total, rows_in / max(rows_all, 1)


def stack(rs: list[Result]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Labelled features, labels and weights (each dataset the same total weight)."""
    xs, ys, ws = [], [], []
    for d in sorted({r.dataset for r in rs}):
        part = [r for r in rs if r.dataset == d]
        x = np.vstack([r.features[r.label >= 0] for r in part])
        y = np.concatenate([r.label[r.label >= 0] for r in part]).astype(float)
        xs.append(x)
        ys.append(y)
        ws.append(np.full(len(y), 1.0 / max(len(y), 1)))
    w = np.concatenate(ws)
    return np.vstack(xs), np.concatenate(ys), w * len(w) / w.sum()


def plot(curves: dict[str, tuple[np.ndarray, np.ndarray, np.ndarray, float]], path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (ax, hx) = plt.subplots(2, 1, figsize=(5.5, 6.5), height_ratios=(3, 1), sharex=True)
    ax.plot([0, 1], [0, 1], color="0.6", lw=1, ls="--", label="perfectly calibrated")
    centres = (np.arange(BINS) + 0.5) / BINS
    for k, (name, (mp, my, n, e)) in enumerate(curves.items()):
        seen = n > 0
        ax.plot(mp[seen], my[seen], marker="o", ms=4, label=f"{name} left out (ECE {e:.3f})")
        hx.bar(centres + (k - 1.5) * 0.022, n / n.sum(), width=0.022, label=name)
    ax.set_ylabel("share of rows whose identity is right")
    ax.set_title("Confidence per row, each dataset left out of the fit")
    ax.legend(fontsize=8, loc="upper left")
    ax.set_xlim(0, 1)
    ax.set_ylim(0, 1)
    hx.set_xlabel("confidence (column 7 of the result)")
    hx.set_ylabel("share of rows")
    fig.tight_layout()
    fig.savefig(path, dpi=110)


def main() -> None:
    t0 = time.process_time()
    rs = results()
    print(f"\n{len(rs)} results; features {', '.join(FEATURES)}; threshold {THRESHOLD}; 10 equal-width bins\n")
    print("left out     | rows    | ECE   (constant) | Brier | AUC   | ECE per kind               | switches in "
          "a range | rows in a range")
    curves = {}
    for d in DATASETS:
        train = [r for r in rs if r.dataset != d]
        test = [r for r in rs if r.dataset == d]
        x, y, w = stack(train)
        coef = fit(x, y, w)
        base = float(np.average(y, weights=w))
        probs = [logistic(r.features, coef) for r in test]
        keep = np.concatenate([r.label >= 0 for r in test])
        p = np.concatenate(probs)[keep]
        yt = np.concatenate([r.label for r in test])[keep].astype(float)
        e, mp, my, n = ece(p, yt)
        e0 = ece(np.full(len(yt), base), yt)[0]
        kinds = []
        for kind in ("online", "closed-offline"):
            part = [(r, q) for r, q in zip(test, probs) if r.kind == kind]
            if part:
                kp = np.concatenate([q[r.label >= 0] for r, q in part])
                ky = np.concatenate([r.label[r.label >= 0] for r, q in part]).astype(float)
                kinds.append(f"{kind} {ece(kp, ky)[0]:.3f}")
        inside, total, share = switch_share(test, probs, THRESHOLD)
        curves[d] = (mp, my, n, e)
        print(f"{d:12s} | {len(yt):7d} | {e:.3f} ({e0:.3f})    | {np.mean((p - yt) ** 2):.3f} | {auc(p, yt):.3f} | "
              f"{'; '.join(kinds):26s} | {inside}/{total} = {inside / max(total, 1):.1%}   | {share:.1%}")
        explore = []
        for th in EXPLORE:
            i2, t2, s2 = switch_share(test, probs, th)
            explore.append(f"<{th}: {i2 / max(t2, 1):.1%} of switches, {s2:.1%} of rows")
        print(f"{'':12s}   exploratory: " + "; ".join(explore))
        print(f"{'':12s}   coefficients fitted without it: " + ", ".join(f"{c:.4f}" for c in coef))
    x, y, w = stack(rs)
    coef = fit(x, y, w)
    print("\nshipped (fitted on all four datasets): COEFFICIENTS = (" + ", ".join(f"{c:.4f}" for c in coef) + ")")
    print("  order: intercept, " + ", ".join(FEATURES))
    plot(curves, ROOT / "docs" / "images" / "confidence-reliability.png")
    print(f"({time.process_time() - t0:.0f} s CPU)")


if __name__ == "__main__":
    sys.exit(main())
