"""Pigs, closed set of 23 offline: ``track_closed_set`` as ``lookalike track det.txt -t boxtrack --targets 23
--offline`` runs it (boxtrack's defaults online, the closed set's defaults offline), on the video's first
half (where closed-set choices may be made), second half (unseen by them) and the whole dev video.

``--set KEY=VALUE`` overrides a :class:`~lookalike.trackers.offline.closed_set.ClosedSetConfig` field, to compare
variants; say which half a choice was made on. Run::

    python benchmarks/closed_pigs.py [--data ../shared/data] [--parts first,second,full] [--set jump=4]
"""

from __future__ import annotations

import argparse
import math
import time
from dataclasses import fields

import numpy as np

from lookalike.bench.datasets import cut_sequence, load_boxes, resolve_data_root
from lookalike.bench.runner import score_rows
from lookalike.trackers.offline.closed_set import ClosedSetConfig, assign_identities, online_rows


def det_rows(seq: object) -> np.ndarray:
    out = [[k + 1, -1, *b, s, -1, -1, -1] for k in range(seq.length)  # type: ignore[attr-defined]
           for b, s in zip(seq.det_xywh[k], seq.det_score[k])]  # type: ignore[attr-defined]
    return np.array(out, dtype=float).reshape(-1, 10)


def parse_overrides(specs: list[str]) -> dict[str, object]:
    types = {f.name: f.type for f in fields(ClosedSetConfig)}
    out: dict[str, object] = {}
    for spec in specs:
        key, _, text = spec.partition("=")
        if key not in types:
            raise SystemExit(f"--set: unknown ClosedSetConfig field {key!r}")
        out[key] = None if text == "None" else math.inf if text == "inf" else (
            int(text) if "int" in str(types[key]) and "float" not in str(types[key]) else float(text))
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n", 1)[0])
    ap.add_argument("--data", default=None)
    ap.add_argument("--parts", default="first,second,full")
    ap.add_argument("--set", action="append", default=[], dest="overrides")
    args = ap.parse_args()
    root = resolve_data_root(args.data)
    cfg = ClosedSetConfig(**parse_overrides(args.overrides))  # type: ignore[arg-type]
    full = load_boxes(root / "pigs", "pigs")[0]
    print(f"closed set {cfg}" if args.overrides else "closed set defaults")
    for part in args.parts.split(","):
        seq = cut_sequence(full, part)
        det = det_rows(seq)
        t0 = time.process_time()
        on = online_rows(det, seq.frame_rate, seq.length, n_init=1)
        rows = assign_identities(on, 23, seq.frame_rate, cfg)
        s = score_rows(seq, rows)
        label = {"first": "first half (choices)", "second": "second half (unseen)", "full": "whole dev video"}[part]
        print(f"pigs {label:<22} IDF1 {100 * s['IDF1']:.2f}  HOTA {100 * s['HOTA']:.2f}  MOTA {100 * s['MOTA']:.2f}  "
              f"IDSW {int(s['IDSW'])}  ids {len(np.unique(rows[:, 1]))}  ({time.process_time() - t0:.0f} s CPU)",
              flush=True)


if __name__ == "__main__":
    main()
