"""Step time of the set identifier (target: <= 1 ms per frame for N = 7 on one core).

Run: ``python benchmarks/set_speed.py [--frames 2000]``. Runs the registered ``set`` identifier
(numpy network, one-to-one decoding and the agents' positions from the shared Kalman localiser) and
the ``lstm`` identifier (same localiser) over a simulated M=10, N=7 sequence, interleaved frame by
frame, and prints the median CPU time per frame of the network step alone (the target) and of
the whole identifier update beside the LSTM's and beside ``set`` without its report-exchange detector.
Set ``OMP_NUM_THREADS=1`` for one core.
"""

from __future__ import annotations

import argparse
import statistics
import time

import numpy as np
from _common import report_target

from lookalike.sim import preset, simulate_robots
from lookalike.trackers import make_tracker
from lookalike.trackers.set.network import agent_tokens, detection_tokens


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--frames", type=int, default=2000, help="frames of the M=10, N=7 sequence")
    args = parser.parse_args()
    cfg = preset("m10n7")
    frames = list(simulate_robots(cfg, args.frames, 12345).frames())
    tracker = make_tracker("set", n_agents=cfg.n_agents, n_slots=cfg.max_detections)
    peer = make_tracker("lstm", n_agents=cfg.n_agents, n_slots=cfg.max_detections)
    plain = make_tracker("set", n_agents=cfg.n_agents, n_slots=cfg.max_detections, exchange_llr=None)
    update, peer_update, plain_update, step = [], [], [], []
    for frame in frames:
        t0 = time.process_time()
        tracker.update(frame)
        t1 = time.process_time()
        peer.update(frame)
        t2 = time.process_time()
        plain.update(frame)
        update.append(t1 - t0)
        peer_update.append(t2 - t1)
        plain_update.append(time.process_time() - t2)
    net = tracker.net
    net.reset(cfg.n_agents)
    rng = np.random.default_rng(0)
    agents = agent_tokens(rng.uniform(-3, 3, cfg.n_agents), rng.uniform(0, 1, cfg.n_agents))
    for _ in range(args.frames):
        dets = detection_tokens(rng.uniform(0, 6, (cfg.max_detections, 2)), rng.uniform(-3, 3, cfg.max_detections),
                                rng.uniform(0.3, 1, cfg.max_detections))
        t0 = time.process_time()
        net.step(agents, dets, 1 / 30)
        step.append(time.process_time() - t0)
    step_ms, update_ms = 1000 * statistics.median(step), 1000 * statistics.median(update)
    peer_ms = 1000 * statistics.median(peer_update)
    print(f"M=10, N=7, {args.frames} frames (median CPU time): network step {step_ms:.3f} ms (10 detections); "
          f"identifier update {update_ms:.3f} ms per frame, lstm's {peer_ms:.3f} ms (ratio {update_ms / peer_ms:.2f}); "
          f"without the report-exchange detector (exchange_llr=None) {1000 * statistics.median(plain_update):.3f} ms")
    report_target("set network step time, N=7 (ms/frame)", step_ms, 1.0, higher_is_better=False)


if __name__ == "__main__":
    main()
