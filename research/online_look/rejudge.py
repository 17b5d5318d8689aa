"""Development run of rejudge-rule.md: the `--online` rows with the shipped look layer (a crossing judged when its
new piece reaches 8 rows) and with the layer that judges it again at 16, 32, 64 and 128 rows, on the 30 development
arenas and the 14 HexBug clips. Run from the repository root:
``OMP_NUM_THREADS=1 .venv/bin/python research/online_look/rejudge.py [arenas,hexbug] [SEEDS]``"""
import sys
from pathlib import Path

import dev
import scoring

from lookalike.trackers.offline import online_look

AGAIN = (8, 16, 32, 64, 128)
MODES = ("shipped", "again")
work = Path("/tmp/online-look-rejudge")


def run(video, n):
    found, fps = scoring.detected(video, n, work)
    rows, vecs = dev.online(found, fps, n)
    out, changes = [], []
    for judge_at in (online_look.JUDGE_AT, AGAIN):
        kept, online_look.JUDGE_AT = online_look.JUDGE_AT, judge_at
        try:
            r, c = dev.relabel(rows, vecs, fps, online_look.LOOK_THRESHOLD)
        finally:
            online_look.JUDGE_AT = kept
        out.append(r)
        changes.append(c)
    print(f"  re-assignments shipped / again: {changes}", flush=True)
    return out


if __name__ == "__main__":
    seeds = [int(s) for s in sys.argv[2].split(",")] if len(sys.argv) > 2 else (*range(10), *range(4000, 4020))
    scoring.main(run, MODES, work, seeds=seeds)
