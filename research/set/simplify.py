"""Does each of ``set``'s mechanisms earn its place? The one scoring run of research/set/simplify-rule.md.

Per set-up (M=3,N=2; M=5,N=3; M=10,N=7 and the unseen N=4, 6, 12 of benchmarks/set_teams.py) the first 100
sequences of a fresh seed block whose swap is measurable (``lookalike.bench.experiments.measurable``); on each,
every candidate (the shipped ``set`` and ``set`` with one group of mechanisms off) and the references run twice: on
the clean sequence (identification: % of detections labelled correctly, as ``bench ident``) and with the two robots
seen most swapping reports from 5 s for 10 s (recovery: seconds until the swapped run's success on the pair is back
within 5% of the clean run's, as ``bench recovery``; never: the longest the sequence can measure).

Sequences are interleaved (sequence k of every set-up and candidate before sequence k + 1), one line of JSON per
(set-up, sequence, identifier) in ``--out``, so that a stopped run resumes and a cut-off one has the same sequences
for every candidate. ``--report`` prints the table and the rule's decision from ``--out``; ``--markdown`` the tables
of docs/experiments/any-team-size.md. ``--extra NAME=JSON`` scores one more ``set`` configuration on the same
sequences after the decision (the identifier that ships when several groups were dropped); it decides nothing.

    OMP_NUM_THREADS=1 python research/set/simplify.py --out runs/set-simplify/runs.jsonl
    python research/set/simplify.py --out runs/set-simplify/runs.jsonl --report
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path
from typing import Any

import numpy as np

from lookalike.bench.experiments import longest_recovery_s, measurable, swap_recovery
from lookalike.bench.ident import identify
from lookalike.bench.paired import PairedDifference, mean_difference, rate_difference
from lookalike.eval.identification import identification_counts
from lookalike.learn.set_data import world
from lookalike.sim import RobotWorldConfig, preset, simulate_robots

SEED = 5_000_000  # fresh: every seed used before is below 4_400_000 (docs/experiments/any-team-size.md)
FRAMES, SWAP_AT_S, SWAP_S = 900, 5.0, 10.0
# Groups of mechanisms switched off together (parameters of the identifier as shipped before the simplification).
CANDIDATES: dict[str, dict[str, Any]] = {
    "full": {},
    "no-report-jumps": {"report_jump": None},
    "no-report-exchange": {"exchange_llr": None},
    "no-visual-exchange": {"visual_exchange": None},
    "no-corrections": {"stale_s": None, "fp_prior_ref": None, "undo_factor": None},
}
RULE_CANDIDATES = tuple(CANDIDATES)
REFERENCES = ("lstm",)  # shipped for the paper's set-ups only


def setups() -> list[tuple[str, RobotWorldConfig, bool]]:
    """(name, world, whether an LSTM ships for it)."""
    out = [(p, preset(p), True) for p in ("m3n2", "m5n3", "m10n7")]
    out += [(f"m{m}n{n}", world(n, m, fp), False) for n, m, fp in ((4, 6, 1.0), (6, 8, 1.3), (12, 14, 2.5))]
    return out


def score(name: str, options: dict[str, Any], seq: Any) -> dict[str, float]:
    """Identification counts on the clean run and the recovery figures of one identifier on one sequence."""
    clean: list[list[np.ndarray]] = []

    def labels(s: Any, fs: Any) -> list[np.ndarray]:
        out = identify(name, s, fs, options=options)
        clean.append(out)
        return out

    run = swap_recovery(labels, seq, SWAP_AT_S, SWAP_S)
    correct, detections = identification_counts(clean[0], seq.true_labels())
    return {"correct": int(correct), "detections": int(detections), **{k: float(v) for k, v in run._asdict().items()}}


def collect(out: Path, sequences: int, only: set[str] | None = None) -> None:
    done = set()
    if out.exists():
        for line in out.read_text().splitlines():
            r = json.loads(line)
            done.add((r["setup"], r["k"], r["id"]))
    out.parent.mkdir(parents=True, exist_ok=True)
    plan = setups()
    next_seed = {name: SEED + 10_000 * i for i, (name, _, _) in enumerate(plan)}
    t0 = time.time()
    with out.open("a") as f:
        for k in range(sequences):
            for name, cfg, has_lstm in plan:
                while True:  # the next measurable sequence of this set-up's block (from the truth alone)
                    seed = next_seed[name]
                    next_seed[name] += 1
                    seq = simulate_robots(cfg, FRAMES, seed)
                    if measurable(seq, SWAP_AT_S, SWAP_S):
                        break
                ids = list(CANDIDATES) + [r for r in REFERENCES if has_lstm]
                for ident in ids:
                    if (name, k, ident) in done or (only is not None and ident not in only):
                        continue
                    tracker, options = ("set", CANDIDATES[ident]) if ident in CANDIDATES else (ident, {})
                    row = {"setup": name, "k": k, "seed": seed, "id": ident, **score(tracker, options, seq)}
                    f.write(json.dumps(row) + "\n")
                    f.flush()
            print(f"sequence {k + 1}/{sequences} of every set-up done, {time.time() - t0:.0f} s", flush=True)


def text(d: PairedDifference, unit: str) -> str:
    return f"{d.difference:+.2f}{unit} [{d.low:+.2f}, {d.high:+.2f}]"


def report(out: Path) -> None:
    rows = [json.loads(line) for line in out.read_text().splitlines()]
    keep: dict[str, list[str]] = {c: [] for c in RULE_CANDIDATES if c != "full"}
    for name, cfg, _ in setups():
        longest = longest_recovery_s(FRAMES, cfg.frame_rate_hz, SWAP_AT_S, SWAP_S)
        by_id: dict[str, dict[int, dict]] = {}
        for r in rows:
            if r["setup"] == name:
                by_id.setdefault(r["id"], {})[r["k"]] = r
        ruled = [v for i, v in by_id.items() if i in RULE_CANDIDATES or i in REFERENCES]
        ks = sorted(set.intersection(*(set(v) for v in ruled)))
        print(f"\n{name}: {len(ks)} sequences (every identifier)")
        full = [by_id["full"][k] for k in ks]
        for ident, per_k in by_id.items():
            if any(k not in per_k for k in ks):
                print(f"  {ident}: {len(per_k)} sequences only, left out")
                continue
            rs = [per_k[k] for k in ks]
            ident_pct = 100 * sum(r["correct"] for r in rs) / max(1, sum(r["detections"] for r in rs))
            rec = [min(r["recovery_s"], longest) for r in rs]
            never = sum(np.isinf(r["recovery_s"]) for r in rs)
            line = (f"  {ident:20s} ident {ident_pct:6.2f}%  recovery {np.mean(rec):5.2f} s "
                    f"(worst {max(rec):5.2f}, never {never})")
            if ident != "full":
                di = rate_difference([r["correct"] for r in rs], [r["correct"] for r in full],
                                     [r["detections"] for r in rs])
                dr = mean_difference(rec, [min(r["recovery_s"], longest) for r in full])
                line += f"  vs full: ident {text(di, ' pts')}, recovery {text(dr, ' s')}"
                if ident in keep:
                    if di.high < 0:
                        keep[ident].append(f"{name} identification")
                    if dr.low > 0:
                        keep[ident].append(f"{name} recovery")
            print(line)
    print("\nDecision (a group stays when removing it lowers identification or raises recovery beyond the paired "
          "95% interval on at least one set-up):")
    for ident, why in keep.items():
        print(f"  {ident:20s} {'KEEP (' + ', '.join(why) + ')' if why else 'DROP'}")


def markdown(out: Path, shipped: str) -> None:
    """The docs' tables: ``shipped`` (a candidate or extra) against the LSTM, and each group switched off against
    ``full``; paired 95% intervals over the sequences every identifier of the row completed."""
    rows = [json.loads(line) for line in out.read_text().splitlines()]
    per: dict[tuple[str, str], dict[int, dict]] = {}
    for r in rows:
        per.setdefault((r["setup"], r["id"]), {})[r["k"]] = r
    label = {"m3n2": "M=3, N=2", "m5n3": "M=5, N=3", "m10n7": "M=10, N=7", "m6n4": "M=6, N=4 (unseen)",
             "m8n6": "M=8, N=6 (unseen)", "m14n12": "M=14, N=12 (unseen)"}

    def pair(setup: str, a: str, b: str, longest: float) -> tuple[str, str, str, str, int]:
        ka, kb = per.get((setup, a), {}), per.get((setup, b), {})
        ks = sorted(set(ka) & set(kb))
        ra, rb = [ka[k] for k in ks], [kb[k] for k in ks]
        rate = [100 * sum(r["correct"] for r in x) / sum(r["detections"] for r in x) for x in (ra, rb)]
        rec = [[min(r["recovery_s"], longest) for r in x] for x in (ra, rb)]
        di = rate_difference([r["correct"] for r in ra], [r["correct"] for r in rb], [r["detections"] for r in ra])
        dr = mean_difference(rec[0], rec[1])
        return (f"{rate[0]:.2f} / {rate[1]:.2f}", text(di, ""), f"{np.mean(rec[0]):.2f} / {np.mean(rec[1]):.2f}",
                text(dr, ""), len(ks))

    print(f"| set-up | identification %, {shipped} / lstm | difference, points [95%] | recovery s, {shipped} / lstm "
          "| difference, s [95%] | sequences |\n|---|---|---|---|---|---|")
    for name, cfg, has_lstm in setups():
        longest = longest_recovery_s(FRAMES, cfg.frame_rate_hz, SWAP_AT_S, SWAP_S)
        if has_lstm:
            a, b, c, d, n = pair(name, shipped, "lstm", longest)
            print(f"| {label[name]} | {a} | {b} | {c} | {d} | {n} |")
        else:
            ks = sorted(per.get((name, shipped), {}))
            rs = [per[(name, shipped)][k] for k in ks]
            rate = 100 * sum(r["correct"] for r in rs) / sum(r["detections"] for r in rs)
            rec = [min(r["recovery_s"], longest) for r in rs]
            print(f"| {label[name]} | {rate:.2f} / - | - | {np.mean(rec):.2f} / - | - | {len(ks)} |")
    groups = [c for c in RULE_CANDIDATES if c != "full"]
    print("\n| set-up | " + " | ".join(groups) + " |\n|---|" + "---|" * len(groups))
    for name, cfg, _ in setups():
        longest = longest_recovery_s(FRAMES, cfg.frame_rate_hz, SWAP_AT_S, SWAP_S)
        cells = []
        for g in groups:
            _, b, _, d, _ = pair(name, g, "full", longest)
            cells.append(f"{b} pts; {d} s")
        print(f"| {label[name]} | " + " | ".join(cells) + " |")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=Path("runs/set-simplify/runs.jsonl"))
    parser.add_argument("--sequences", type=int, default=100, help="measurable sequences per set-up")
    parser.add_argument("--report", action="store_true", help="print the table and the decision only")
    parser.add_argument("--extra", action="append", default=[], help="NAME=JSON: one more set configuration")
    parser.add_argument("--markdown", default=None, help="print the docs' tables for this identifier and stop")
    args = parser.parse_args()
    if args.markdown:
        markdown(args.out, args.markdown)
        return
    extras = dict(e.split("=", 1) for e in args.extra)
    CANDIDATES.update({name: json.loads(options) for name, options in extras.items()})
    if not args.report:
        collect(args.out, args.sequences, set(extras) or None)
    report(args.out)


if __name__ == "__main__":
    main()
