"""The set identifier against the per-size LSTM and the baselines, on team sizes with and without an LSTM.

Run: ``python benchmarks/set_teams.py [--sequences 3] [--frames 1000] [--trackers set,lstm,jpda,kalman_ha2]``.
Prints the identification success rate (%) of each identifier on the paper's set-ups (the sequences of
``lookalike bench ident``: seeds 900000 + 1000·setup + k) and on team sizes no LSTM was trained for
(N = 4, 6, 12 with M = N + 2; seeds 950000 + 1000·N + k), all disjoint from the training seeds.
The LSTM has no weights for the latter ("-"). ``--weights W``: the ``set`` identifier with these weights.

Choosing a fine-tuning snapshot on tuning sequences: ``python research/set/set_select.py``.
"""

from __future__ import annotations

import argparse
from pathlib import Path

from lookalike.bench.ident import DEFAULT_SEED, run_identifier
from lookalike.bench.pixel_recordings import score_identifier
from lookalike.learn.set_data import world
from lookalike.sim import PRESET_NAMES, preset, simulate_robots

# (N, M, false positives per frame): between the presets' clutter (0.5, 0.8, 1.5 for N = 2, 3, 7) and more.
UNSEEN_TEAMS = ((4, 6, 1.0), (6, 8, 1.3), (12, 14, 2.5))
UNSEEN_SEED = 950_000


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--sequences", type=int, default=3, help="sequences per team")
    parser.add_argument("--frames", type=int, default=1000, help="frames per sequence")
    parser.add_argument("--trackers", default="set,lstm,jpda,kalman_ha2", help="identifiers, comma-separated")
    parser.add_argument("--teams", default="presets,unseen", help="presets, unseen or both")
    parser.add_argument("--weights", type=Path, default=None, help="set weights (.npz; default: the shipped ones)")
    args = parser.parse_args()
    names = args.trackers.split(",")
    wanted = {"presets", "unseen"} if args.teams == "both" else set(args.teams.split(","))
    if not wanted or not wanted <= {"presets", "unseen"}:
        parser.error(f"--teams: presets, unseen, presets,unseen or both, got {args.teams!r}")
    teams = []
    if "presets" in wanted:
        teams += [(preset(p), [DEFAULT_SEED + 1000 * PRESET_NAMES.index(p) + k for k in range(args.sequences)])
                  for p in PRESET_NAMES]
    if "unseen" in wanted:
        teams += [(world(n, m, fp), [UNSEEN_SEED + 1000 * n + k for k in range(args.sequences)])
                  for n, m, fp in UNSEEN_TEAMS]
    print(f"{args.sequences} sequences x {args.frames} frames per team; success rate (%), frames/s")
    print("team              " + "".join(f"{n:>18s}" for n in names))
    for cfg, seeds in teams:
        seqs = [simulate_robots(cfg, args.frames, s) for s in seeds]
        cells = []
        for name in names:
            if name == "lstm" and (cfg.max_detections, cfg.n_agents) not in ((3, 2), (5, 3), (10, 7)):
                cells.append(f"{'-':>18s}")
                continue
            if name == "set" and args.weights is not None:
                cells.append(f"{100 * score_identifier(seqs, 'set', weights=str(args.weights))[0]:9.2f} {'':>8s}")
                continue
            r = run_identifier(name, seqs)
            cells.append(f"{100 * r['success']:9.2f} {r['fps']:6.0f}/s")
        label = f"M={cfg.max_detections}, N={cfg.n_agents}, fp={cfg.sensor.fp_per_frame:g}"
        print(f"{label:18s}" + "".join(cells), flush=True)


if __name__ == "__main__":
    main()
