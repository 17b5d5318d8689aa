"""Node soak: 60 s of a random mix of valid and invalid datagrams on loopback, then a
clean final frame. Prints the figures and whether the node stayed alive, bounded and consistent.

    .venv/bin/python benchmarks/node_soak.py [--seconds 60] [--seed 0]
"""

from __future__ import annotations

import argparse
import json

from _common import report_target
from _soak import soak


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seconds", type=float, default=60.0)
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args()
    result = soak(args.seconds, seed=args.seed)
    print(json.dumps(result.summary()))
    c = result.counters
    print(f"counters: received {c.get('received')} reports {c.get('reports')} frames {c.get('frames')} "
          f"queue_dropped {c.get('queue_dropped')} queue_full {c.get('queue_full')} "
          f"rate_limited {c.get('rate_limited')} rejected {c.get('rejected_total')}")
    ok = result.alive and result.consistent() and result.final_ok
    report_target("node soak alive, counters consistent, final team state right", float(ok), 1.0)
    report_target("node soak resident memory growth", result.rss_peak_mb - result.rss_start_mb, 64.0,
                  higher_is_better=False, unit=" MiB")


if __name__ == "__main__":
    main()
