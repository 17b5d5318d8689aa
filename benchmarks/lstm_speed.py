"""Speed of the numpy LSTM association step (M=10, N=7 by default): milliseconds per frame.

``python benchmarks/lstm_speed.py [--agents 7 --slots 10 --frames 3000]``. Uses the shipped weights
when they exist for the set-up, else random weights of the same shape (the cost is the same).
Single-threaded BLAS is what a robot's spare core gives; the figure printed is the median of 5 runs.
"""

from __future__ import annotations

import argparse
import statistics
import time

import numpy as np
from _common import report_target

from lookalike.trackers.lstm import EncodingSpec, NetworkWeights, NumpyAssociationNet, load_weights
from lookalike.trackers.lstm.checkpoint import CheckpointError
from lookalike.trackers.lstm.weights import shipped_weights_path


def _weights(n_agents: int, n_slots: int) -> NetworkWeights:
    try:
        return load_weights(shipped_weights_path(n_agents, n_slots), n_agents, n_slots)
    except CheckpointError:
        spec = EncodingSpec(n_agents, n_slots, relative_headings=True)
        rng, h = np.random.default_rng(0), 64
        layers = [{"w_ih": rng.normal(0, 0.1, (4 * h, spec.n_inputs if i == 0 else h)),
                   "w_hh": rng.normal(0, 0.1, (4 * h, h)), "b_ih": np.zeros(4 * h), "b_hh": np.zeros(4 * h)}
                  for i in range(5)]
        k = n_slots * (n_agents + 1)
        return NetworkWeights(spec, "lstm", h, layers, rng.normal(0, 0.1, (k, h)), np.zeros(k),
                              np.zeros(spec.n_inputs), np.ones(spec.n_inputs))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--agents", type=int, default=7)
    parser.add_argument("--slots", type=int, default=10)
    parser.add_argument("--frames", type=int, default=3000)
    args = parser.parse_args()
    net = NumpyAssociationNet(_weights(args.agents, args.slots))
    x = np.random.default_rng(1).normal(size=(args.frames, net.spec.n_inputs))
    runs = []
    for _ in range(5):
        net.reset()
        t0 = time.perf_counter()
        for row in x:
            net.step(row)
        runs.append((time.perf_counter() - t0) / args.frames * 1e3)
    median_ms = statistics.median(runs)
    print(f"numpy LSTM step, M={args.slots}, N={args.agents}: {median_ms:.3f} ms per frame "
          f"(the paper: 4 ms on the robot)")
    report_target(f"numpy LSTM step M={args.slots} N={args.agents}", median_ms, 0.2, higher_is_better=False,
                  unit=" ms")


if __name__ == "__main__":
    main()
