"""Robot-world simulator speed (DESIGN §11: >= 50,000 frames/s for N = 7).

Run: ``python benchmarks/sim_speed.py [--frames 1000] [--sequences 50]``. Prints frames per second
of :func:`lookalike.sim.simulate_arrays` per preset (arrays only), and of building Frame objects.
"""

from __future__ import annotations

import argparse
import time

from _common import report_target

from lookalike.sim import PRESET_NAMES, preset, simulate_arrays, simulate_robots


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--frames", type=int, default=1000, help="frames per sequence")
    parser.add_argument("--sequences", type=int, default=50, help="sequences per preset")
    args = parser.parse_args()
    for name in PRESET_NAMES:
        cfg = preset(name)
        simulate_arrays(cfg, args.frames, seed=0)  # warm-up
        t0 = time.perf_counter()
        for seed in range(args.sequences):
            simulate_arrays(cfg, args.frames, seed=seed)
        elapsed = time.perf_counter() - t0
        fps = args.sequences * args.frames / elapsed
        seq = simulate_robots(cfg, args.frames, seed=1)
        t0 = time.perf_counter()
        n = sum(1 for _ in seq.frames())
        frame_fps = n / (time.perf_counter() - t0)
        print(f"{name:6s} N={cfg.n_agents} M={cfg.max_detections}: simulate_arrays {fps:10,.0f} frames/s; "
              f"as Frame objects {frame_fps:8,.0f} frames/s")
        if cfg.n_agents == 7:
            report_target(f"simulate_arrays {name}", fps, 50_000, unit=" frames/s")


if __name__ == "__main__":
    main()
