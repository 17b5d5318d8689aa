"""Step time of the set identifier (issue 23: <= 1 ms per frame for N = 7 on one core).

Run: ``python benchmarks/set_speed.py [--frames 2000]``. Runs the registered ``set`` identifier
(numpy network, one-to-one decoding and the agents' positions) over a simulated M=10, N=7 sequence
and prints the median time per frame of the network step alone and of the whole identifier update.
Set ``OMP_NUM_THREADS=1`` for one core.
"""

from __future__ import annotations

import argparse
import statistics
import time

import numpy as np
from _common import report_target

from lookalike.learn.set_data import agent_tokens, detection_tokens
from lookalike.sim import preset, simulate_robots
from lookalike.trackers import make_tracker


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--frames", type=int, default=2000, help="frames of the M=10, N=7 sequence")
    args = parser.parse_args()
    cfg = preset("m10n7")
    frames = list(simulate_robots(cfg, args.frames, 12345).frames())
    tracker = make_tracker("set", n_agents=cfg.n_agents, n_slots=cfg.max_detections)
    update, step = [], []
    for frame in frames:
        t0 = time.perf_counter()
        tracker.update(frame)
        update.append(time.perf_counter() - t0)
    net = tracker.net
    net.reset(cfg.n_agents)
    rng = np.random.default_rng(0)
    agents = agent_tokens(rng.uniform(-3, 3, cfg.n_agents), rng.uniform(0, 1, cfg.n_agents))
    for _ in range(args.frames):
        dets = detection_tokens(rng.uniform(0, 6, (cfg.max_detections, 2)), rng.uniform(-3, 3, cfg.max_detections),
                                rng.uniform(0.3, 1, cfg.max_detections))
        t0 = time.perf_counter()
        net.step(agents, dets, 1 / 30)
        step.append(time.perf_counter() - t0)
    step_ms, update_ms = 1000 * statistics.median(step), 1000 * statistics.median(update)
    print(f"M=10, N=7, {args.frames} frames: network step {step_ms:.3f} ms (10 detections), "
          f"identifier update {update_ms:.3f} ms per frame (median)")
    report_target("set identifier update time, N=7 (ms/frame)", update_ms, 1.0, higher_is_better=False)


if __name__ == "__main__":
    main()
