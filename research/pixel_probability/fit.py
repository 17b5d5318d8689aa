"""Fit the pixel pipeline's detection probability map (:mod:`lookalike.vision.detection_probability`) on
rendered training sequences, so that the probability the identifiers read from pixels is spread like the
simulator's detector score they were trained on.

The margins are those of the detections the pipeline keeps (``min_score``, up to the set-up's M per
frame) on sequences of ``pixel_setups`` rendered from seeds ``seed + 1000·setup + k``; the target is the
simulator's own detector scores on ``sim_sequences`` sequences of each of ``sim_setups`` from the same
seeds. The default ``seed`` 800000 keeps clear of the bench's held-out 700000+ and of the models'
training renders (below 400000). Fit a map with (none is shipped: see research/README.md)::

    python research/pixel_probability/fit.py -o FILE

Writing it to ``src/lookalike/vision/models_data/robot_detection_probability.json`` makes the pipeline read
it by default.
"""

from __future__ import annotations

import argparse
import sys
from typing import Any

import numpy as np

from lookalike.geometry.camera import Camera
from lookalike.parallel import one_blas_thread
from lookalike.sim import PRESET_NAMES, preset, simulate_robots
from lookalike.sim.robot_camera import pixel_camera, world_for_camera
from lookalike.vision.detection_probability import DetectionProbability, fit_quantile_map
from lookalike.vision.pipeline import PipelineConfig, RobotPipeline
from lookalike.viz.robot_pixels import render_robot_frames

FIT_SEED = 800_000


def _seed(setup: str, seed: int, k: int) -> int:
    return seed + 1000 * PRESET_NAMES.index(setup) + k


def pixel_margins(pipe: RobotPipeline, setup: str, sequences: int, frames: int, seed: int,
                  camera: Camera) -> np.ndarray:
    """Last-stage margins of the detections ``pipe``'s perception keeps (up to the preset's M per frame)
    on ``sequences`` rendered sequences of ``setup``."""
    cfg = world_for_camera(preset(setup), camera)
    config = PipelineConfig(n_agents=cfg.n_agents, max_detections=cfg.max_detections, min_score=pipe.config.min_score,
                            detect_scale=pipe.config.detect_scale)
    margin_of = _Margins()
    seeing = RobotPipeline(pipe.detector, pipe.heading, camera, config, margin_of)
    out: list[np.ndarray] = []
    for k in range(sequences):
        seq = simulate_robots(cfg, frames, _seed(setup, seed, k))
        a = seq.arrays
        for i, rendered in enumerate(render_robot_frames(seq, camera, seed=seq.seed)):
            out.append(seeing.perceive(rendered.image, float(a.observer[i, 2])).score)
    return np.concatenate(out) if out else np.zeros(0)


class _Margins:
    """A "probability" that is the margin itself (to read the kept detections' margins)."""

    def __call__(self, margins: np.ndarray) -> np.ndarray:
        return np.asarray(margins, float)


def simulated_scores(setup: str, sequences: int, frames: int, seed: int, camera: Camera) -> np.ndarray:
    """The simulator's detector scores of every detection of ``sequences`` sequences of ``setup``."""
    cfg = world_for_camera(preset(setup), camera)
    scores = [simulate_robots(cfg, frames, _seed(setup, seed, k)).arrays.det_score for k in range(sequences)]
    return np.concatenate([s[s > 0] for s in scores])


def fit_pixel_probability(pipe: RobotPipeline, camera: Camera, pixel_setups: list[str], sequences: int,
                          frames: int, sim_setups: list[str], sim_sequences: int,
                          seed: int = FIT_SEED) -> DetectionProbability:
    """Quantile map from the pipeline's margins on rendered ``pixel_setups`` sequences to the simulator's
    scores on ``sim_setups`` sequences (all from seeds ``seed + 1000·setup + k``)."""
    if not callable(getattr(pipe.detector, "boxes_and_margins", None)):
        raise ValueError("detector: has no last-stage margins (boxes_and_margins); only the HOG cascade does")
    margins = np.concatenate([pixel_margins(pipe, s, sequences, frames, seed, camera) for s in pixel_setups])
    target = np.concatenate([simulated_scores(s, sim_sequences, frames, seed, camera) for s in sim_setups])
    fitted: dict[str, Any] = {
        "method": "quantile map: pixel margins -> simulator detector scores, 101 quantiles",
        "pixel_seeds": [_seed(s, seed, k) for s in pixel_setups for k in range(sequences)],
        "pixel_setups": pixel_setups, "frames": frames, "pixel_detections": int(len(margins)),
        "sim_seeds": [_seed(s, seed, k) for s in sim_setups for k in range(sim_sequences)],
        "sim_setups": sim_setups, "sim_detections": int(len(target)),
        "command": "python research/pixel_probability/fit.py " + " ".join(sys.argv[1:]),
    }
    return fit_quantile_map(margins, target, fitted_on=fitted)


def main(argv: list[str] | None = None) -> int:
    """``python research/pixel_probability/fit.py -o FILE``: fit and write the map."""
    ap = argparse.ArgumentParser(prog="python research/pixel_probability/fit.py", description=__doc__)
    ap.add_argument("-o", "--output", required=True, help="JSON file to write")
    ap.add_argument("--pixel-setups", default="m10n7", help="presets rendered for the margins")
    ap.add_argument("--sequences", type=int, default=2, help="rendered sequences per pixel set-up")
    ap.add_argument("--frames", type=int, default=300, help="frames per sequence")
    ap.add_argument("--sim-setups", default="m3n2,m5n3,m10n7", help="presets whose simulated scores are the target")
    ap.add_argument("--sim-sequences", type=int, default=10, help="simulated sequences per target set-up")
    ap.add_argument("--seed", type=int, default=FIT_SEED, help="base seed (keep clear of the bench's 700000+)")
    args = ap.parse_args(argv)
    pix, sim = args.pixel_setups.split(","), args.sim_setups.split(",")
    for name in pix + sim:
        if name not in PRESET_NAMES:
            print(f"preset {name!r}: expected one of {', '.join(PRESET_NAMES)}", file=sys.stderr)
            return 2
    camera = pixel_camera()
    pipe = RobotPipeline.from_files(camera=camera)
    with one_blas_thread():
        fitted = fit_pixel_probability(pipe, camera, pix, args.sequences, args.frames, sim, args.sim_sequences,
                                       args.seed)
    fitted.save(args.output)
    print(f"wrote {args.output}: {len(fitted.margin)} knots from {fitted.fitted_on['pixel_detections']} pixel and "
          f"{fitted.fitted_on['sim_detections']} simulated detections")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
