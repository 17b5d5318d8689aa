"""Is ``set``'s recovery after a forced swap no worse than the LSTM's? A non-inferiority test on a large sample.

Runs ``bench recovery``'s experiment (two robots' reports swapped from 5 s for 10 s, the time until the swapped
run's success on the pair is back within 5% of the clean run's) on ``--sequences`` sequences per set-up, and per
set-up prints each identifier's mean recovery, its success on the pair in the 3 s after the restore and while
swapped (each also without the swap), and the 95% interval of the mean of candidate − reference (seconds, over
sequences). The candidate is no worse when the interval's upper end is at most ``--margin`` seconds (a TARGET line
per set-up). A sequence in which an identifier never recovers counts, for that identifier, as the longest recovery
the sequence can measure (from the restore to the last one-second window). ``--candidate-options`` (JSON) gives the
candidate parameters other than its defaults (a development sample's candidates). The figures are kept in ``--out``
per set-up and identifier, so that an interrupted run resumes and a reference runs once for several candidates. The
test, its samples (seeds 3200000+; 3300000+, 3400000+ and 3500000+ for the identifiers of the eleventh, fourteenth
and fifteenth stages; 3600000+ for the check of where the gap sits; 3700000+ for the seventeenth stage's) and
margin are in docs/experiments/any-team-size.md.

Two further figures per set-up (each sequence's runs are kept for them): the same difference on the restores whose
pair's reports differ by at least ``--gap`` radians in the second after the restore and on the others
(:func:`~lookalike.bench.experiments.restore_gap`: how much the reports can tell the two robots apart there), and
the difference in plain success on the pair in the 3 s after the restore (percentage points, 95% interval; no
worse when its lower end is at least ``-success-margin``). They were added after the fifteenth stage's test
(docs/experiments/any-team-size.md, "What the remaining gap is made of"). After the eighteenth stage's test, the
difference on the restores whose reports differ by less than ``--unobservable`` radians (under twice the simulated
IMU's noise: the identifiers' data barely tells the pair apart) and on all the others.

    python research/set/recovery_sample.py --sequences 400 --seed 3500000 --setups m10n7
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np

from lookalike.bench.experiments import (
    APART_RAD,
    SwapRun,
    longest_recovery_s,
    measured_sequences,
    restore_gap,
    swap_runs,
)
from lookalike.bench.paired import PairedDifference, interval_text, mean_difference
from lookalike.sim import preset, preset_label


def report_target(name: str, value: float, target: float, *, higher_is_better: bool = True, unit: str = "") -> bool:
    """Print one target line, ``TARGET <name>: <value> (target >= or <= <target>) PASS|FAIL``; whether it passed."""
    passed = value >= target if higher_is_better else value <= target
    op = ">=" if higher_is_better else "<="
    print(f"TARGET {name}: {value:.3g}{unit} (target {op} {target:g}{unit}) {'PASS' if passed else 'FAIL'}", flush=True)
    return passed


AFTER, RECOVERY = SwapRun._fields.index("after_restore"), SwapRun._fields.index("recovery_s")


def gaps(setup: str, sequences: int, frames: int, seed: int, out: Path, swap_at_s: float, swap_s: float) -> np.ndarray:
    """:func:`restore_gap` of each measured sequence (radians; NaN: a pair member sent nothing), kept in ``out``."""
    cache = out / f"{setup}-{seed}-{sequences}x{frames}-gaps.json"
    if not cache.exists():
        measured = measured_sequences(setup, sequences, frames, seed, swap_at_s, swap_s)
        cache.write_text(json.dumps([restore_gap(q, swap_at_s, swap_s) for q in measured]))
    return np.array(json.loads(cache.read_text()), dtype=float)


def line(name: str, diff: PairedDifference, unit: str) -> str:
    """One printed figure: ``name``, its sequences and the difference with its interval."""
    return f"{name}: {diff.n_sequences} sequences, {diff.difference:+.3f}{unit} ({interval_text(diff, 3)})"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--setups", default="m3n2,m5n3,m10n7")
    parser.add_argument("--candidate", default="set")
    parser.add_argument("--candidate-options", type=json.loads, default={},
                        help='JSON of the candidate\'s parameters, e.g. \'{"exchange_lag_s": 0.3}\'')
    parser.add_argument("--reference", default="lstm")
    parser.add_argument("--sequences", type=int, default=20, help="Per set-up (the test in the docs: 400).")
    parser.add_argument("--frames", type=int, default=900)
    parser.add_argument("--seed", type=int, default=3200000)
    parser.add_argument("--margin", type=float, default=0.15, help="Seconds the candidate may be slower.")
    parser.add_argument("--out", type=Path, default=Path("runs/set-recovery-sample"))
    parser.add_argument("--gap", type=float, default=APART_RAD,
                        help="Radians between the pair's reports after the restore that split the further figures.")
    parser.add_argument("--unobservable", type=float, default=0.05,
                        help="Radians between the pair's reports under which no identifier can tell the two apart.")
    parser.add_argument("--success-margin", type=float, default=2.0,
                        help="Percentage points of success after the restore the candidate may be lower.")
    args = parser.parse_args()
    swap_at_s, swap_s = 5.0, 10.0
    trackers = [args.candidate, args.reference]
    args.out.mkdir(parents=True, exist_ok=True)
    options = {args.candidate: args.candidate_options}
    for setup in args.setups.split(","):
        kept: dict[str, dict] = {}  # identifier -> its recovery seconds per sequence and its row
        for name in trackers:
            tag = "".join(f",{k}={v}".replace("/", "_") for k, v in sorted((options.get(name) or {}).items()))
            cache = args.out / f"{setup}-{args.seed}-{args.sequences}x{args.frames}-{name}{tag}.json"
            if not cache.exists():
                rows, runs = swap_runs([setup], [name], args.sequences, args.frames, swap_at_s, swap_s,
                                       args.seed, options=options)
                run = runs[(setup, name)]
                cache.write_text(json.dumps({"seconds": run[:, RECOVERY].tolist(),
                                             "row": rows[0], "runs": run.tolist(),
                                             "options": options.get(name) or {}}))
            kept[name] = json.loads(cache.read_text())
        seconds = {name: kept[name]["seconds"] for name in trackers}
        longest = longest_recovery_s(args.frames, preset(setup).frame_rate_hz, swap_at_s, swap_s)
        values = {name: [min(s, longest) for s in seconds[name]] for name in trackers}  # never: the longest
        never = {name: int(np.isinf(seconds[name]).sum()) for name in trackers}
        diff = mean_difference(values[args.candidate], values[args.reference])
        label = preset_label(setup)
        print(f"{label}: {len(values[args.candidate])} sequences measured; mean recovery (s) "
              + ", ".join(f"{n} {np.mean(values[n]):.3f} (worst {max(values[n]):.2f}, never {never[n]})"
                          for n in trackers)
              + f"; {args.candidate} - {args.reference} {diff.difference:+.3f} s ({interval_text(diff, 3)})",
              flush=True)
        for row in (kept[name]["row"] for name in trackers):
            print(f"  {row['Tracker']}: success on the pair in the 3 s after the restore "
                  f"{row['After the restore, 3 s (%)']}% ({row['Same without swap, after (%)']}% without the swap), "
                  f"while swapped {row['Swapped robots while swapped (%)']}% ({row['Same without swap (%)']}%)")
        report_target(f"{args.candidate} recovery no worse than {args.reference}, {label} "
                      f"(upper end of the 95% interval of the mean difference)", diff.high, args.margin,
                      higher_is_better=False, unit=" s")
        if not all("runs" in kept[name] for name in trackers):
            print("  (no per-sequence runs in the cache: the further figures need a fresh run)")
            continue
        gap = gaps(setup, args.sequences, args.frames, args.seed, args.out, swap_at_s, swap_s)
        cand, ref = (np.array(values[n]) for n in trackers)
        for text, part in ((f"reports >= {args.gap} rad apart after the restore", gap >= args.gap),
                           (f"reports < {args.gap} rad apart", gap < args.gap),
                           ("a pair member silent in the second after the restore", np.isnan(gap)),
                           (f"reports < {args.unobservable} rad apart (unobservable)", gap < args.unobservable),
                           ("all but those", ~(gap < args.unobservable))):
            print(f"  {line(text, mean_difference(cand[part], ref[part]), ' s')}")
        after = [np.array(kept[n]["runs"], dtype=float).reshape(-1, len(SwapRun._fields))[:, AFTER] * 100
                 for n in trackers]
        seen = np.isfinite(after[0]) & np.isfinite(after[1])
        success = mean_difference(after[0][seen], after[1][seen])
        print(f"  {line('success on the pair in the 3 s after the restore', success, ' points')}")
        report_target(f"{args.candidate} success after the restore no worse than {args.reference}, {label} "
                      f"(lower end of the 95% interval of the mean difference)", success.low, -args.success_margin,
                      unit=" points")


if __name__ == "__main__":
    main()
