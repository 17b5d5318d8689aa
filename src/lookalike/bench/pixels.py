"""The pixels bench (``lookalike bench pixels``): identifiers on detections perceived from rendered frames
(:class:`~lookalike.vision.pipeline.RobotPipeline`) against the simulator's own detections, on held-out sequences
(seeds ``seed + 1000·setup + sequence``). A pixel detection's true robot is the rendered one it overlaps best
(Hungarian on IoU >= ``min_iou``), else it is a false positive."""

from __future__ import annotations

import dataclasses
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from lookalike.bench.ident import check_weights, run_labels, sequence_seeds, setup_results, uses_weights
from lookalike.bench.progress import ProgressFactory
from lookalike.eval import identification_success_rate, localisation_error, robot_success_rate
from lookalike.geometry.boxes import iou_matrix
from lookalike.geometry.camera import Camera
from lookalike.io.results import Results, add_printed_rows
from lookalike.loop import RunStats, run
from lookalike.sim import RobotSequence, preset, preset_label, simulate_robots
from lookalike.sim.robot_camera import identifier_settings, world_for_camera
from lookalike.trackers import make_tracker
from lookalike.trackers.parts.identity import agent_positions
from lookalike.types import Beacons, Detections
from lookalike.vision.pipeline import PipelineConfig, PipelineResult, RobotPipeline
from lookalike.viz.robot_pixels import render_robot_frames

DEFAULT_SEED = 700_000
PIXEL_COLUMNS = ("Setup", "Identifier", "Pixels (%)", "Simulated (%)", "Gap (pp)", "Pixels robots (%)",
                 "Sim robots (%)", "Pixels loc. (m)",
                 "Simulated loc. (m)", "Pixel dets", "Sim dets", "Frames/s")
PERCEPTION_COLUMNS = ("Setup", "Frames", "Recall", "Precision", "Heading error (deg)", "Perception frames/s")


@dataclass
class PerceivedSequence:
    """One sequence after perception: per frame the pixel detections, their true robots (-1: false positive),
    the reports and the time; plus detection and heading statistics."""

    sequence: RobotSequence
    detections: list[Detections] = field(default_factory=list)
    truth: list[np.ndarray] = field(default_factory=list)
    beacons: list[Beacons] = field(default_factory=list)
    times: list[float] = field(default_factory=list)
    matched: int = 0
    robots: int = 0
    heading_errors: list[float] = field(default_factory=list)
    seconds: float = 0.0


def match_truth(det_xywh: np.ndarray, true_xywh: np.ndarray, true_id: np.ndarray, min_iou: float) -> np.ndarray:
    """``(n,)`` robot id of each detection box from one-to-one IoU matching (-1: none >= ``min_iou``)."""
    from scipy.optimize import linear_sum_assignment

    out = np.full(len(det_xywh), -1, dtype=int)
    if len(det_xywh) and len(true_xywh):
        iou = iou_matrix(det_xywh, true_xywh)
        rows, cols = linear_sum_assignment(-iou)
        ok = iou[rows, cols] >= min_iou
        out[rows[ok]] = np.asarray(true_id)[cols[ok]]
    return out


def perceive_sequence(pipe: RobotPipeline, seq: RobotSequence, camera: Camera, min_iou: float,
                      min_visible: float, advance: Any = None) -> PerceivedSequence:
    """Render ``seq`` and run the pipeline's perception on every frame (rendering not timed)."""
    out = PerceivedSequence(seq)
    a = seq.arrays
    for k, rendered in enumerate(render_robot_frames(seq, camera, seed=seq.seed)):
        t0 = time.perf_counter()
        det = pipe.perceive(rendered.image, float(a.observer[k, 2]))
        out.seconds += time.perf_counter() - t0
        assert det.xywh is not None and det.heading is not None  # the pipeline fills both
        truth = match_truth(det.xywh, rendered.xywh, rendered.robot_id, min_iou)
        frame = seq.frame(k)
        out.detections.append(det)
        out.truth.append(truth)
        out.beacons.append(frame.beacons)
        out.times.append(frame.time)
        out.robots += int((rendered.visible >= min_visible).sum())
        visible_ids = set(rendered.robot_id[rendered.visible >= min_visible].tolist())
        out.matched += sum(int(t) in visible_ids for t in truth if t >= 0)
        hit = truth >= 0
        if hit.any():
            true_abs = a.true_heading[k, truth[hit]]
            diff = np.angle(np.exp(1j * (det.heading[hit] - true_abs)))
            out.heading_errors.extend(np.degrees(np.abs(diff)).tolist())
        if advance is not None:
            advance()
    return out


def _identifier(name: str, seq: RobotSequence, camera: Camera, weights: str | None = None) -> PipelineConfig:
    """Identification settings of ``name`` for the sequence and camera (``weights``: .npz for ``lstm``)."""
    params = identifier_settings(name, camera) + ((("weights", weights),) if weights and uses_weights(name) else ())
    return PipelineConfig(identifier=name, n_agents=seq.config.n_agents, max_detections=seq.config.max_detections,
                          identifier_params=params)


class _Identify:
    """Identification of a perceived sequence's frame ``k`` (a tracker of frame indices for :func:`run`)."""

    def __init__(self, pipe: RobotPipeline, perceived: PerceivedSequence) -> None:
        self.pipe, self.p = pipe, perceived

    def update(self, k: int) -> PipelineResult:
        return self.pipe.identify(self.p.detections[k], self.p.beacons[k], self.p.times[k], index=k)


@dataclass
class IdentScore:
    """One identifier on one side (pixels or simulated): success rate (fraction), localisation error (m; NaN: no
    position while in view), detections scored, tracking frames/s and success on true robots only (NaN: none)."""

    success: float
    loc_error: float
    detections: int
    fps: float
    robot_success: float = float("nan")


Labelled = tuple[list[np.ndarray], list[np.ndarray], list[np.ndarray]]  # per frame: labels, positions (N, 2), truth


def _score(perceived: list[PerceivedSequence], labelled: Callable[[PerceivedSequence, RunStats], Labelled]
           ) -> IdentScore:
    """:class:`IdentScore` of ``labelled(sequence, stats)`` over the sequences."""
    predicted: list[np.ndarray] = []
    positions: list[np.ndarray] = []
    truth: list[np.ndarray] = []
    stats = RunStats()
    for p in perceived:
        labels, at, true = labelled(p, stats)
        predicted += labels
        positions += at
        truth += true
    true_positions = [p.sequence.true_positions_visible() for p in perceived]
    loc = localisation_error(np.stack(positions), np.concatenate(true_positions)) if positions else float("nan")
    return IdentScore(identification_success_rate(predicted, truth), loc, sum(len(t) for t in truth), stats.fps,
                      robot_success_rate(predicted, truth))


def score_pixels(name: str, perceived: list[PerceivedSequence], pipe: RobotPipeline, camera: Camera,
                 weights: str | None = None) -> IdentScore:
    """Identifier ``name`` on the pixel detections."""
    def labelled(p: PerceivedSequence, stats: RunStats) -> Labelled:
        labels: list[np.ndarray] = []
        positions: list[np.ndarray] = []

        def sink(k: int, result: PipelineResult) -> None:
            labels.append(result.labels)
            positions.append(agent_positions(result.tracks, p.sequence.config.n_agents))

        config = _identifier(name, p.sequence, camera, weights)
        step = _Identify(RobotPipeline(pipe.detector, pipe.heading, camera, config, pipe.probability), p)
        run(step, range(len(p.detections)), sink, stats=stats)
        return labels, positions, p.truth

    return _score(perceived, labelled)


def score_simulated(name: str, perceived: list[PerceivedSequence], camera: Camera,
                    weights: str | None = None) -> IdentScore:
    """Identifier ``name`` on the simulator's own detections of the same sequences."""
    def labelled(p: PerceivedSequence, stats: RunStats) -> Labelled:
        tracker = make_tracker(name, **_identifier(name, p.sequence, camera, weights).identifier_kwargs())
        labels, at = run_labels(tracker, list(p.sequence.frames()), p.sequence.config.n_agents, stats)
        return labels, list(at), p.sequence.true_labels()

    return _score(perceived, labelled)


def perception_pipeline(pipe: RobotPipeline, n_agents: int, max_detections: int) -> RobotPipeline:
    """``pipe`` keeping up to ``max_detections`` detections per frame for ``n_agents`` robots."""
    config = dataclasses.replace(pipe.config, n_agents=n_agents, max_detections=max_detections)
    return RobotPipeline(pipe.detector, pipe.heading, pipe.camera, config, pipe.probability)


def pixels_table(setups: list[str], identifiers: list[str], sequences: int, frames: int, seed: int,
                 pipe: RobotPipeline, camera: Camera, min_iou: float,
                 progress: ProgressFactory | None = None, weights: str | None = None
                 ) -> tuple[list[dict[str, Any]], list[dict[str, Any]]]:
    """Rows of the identification (:data:`PIXEL_COLUMNS`) and perception (:data:`PERCEPTION_COLUMNS`) tables;
    ``weights``: exported LSTM .npz for the ``lstm`` rows on both sides (one set-up only)."""
    check_weights(weights, setups, identifiers)
    rows, perception = [], []
    for setup in setups:
        cfg = world_for_camera(preset(setup), camera)
        advance = progress(f"{setup}: rendering + perception", sequences * frames) if progress else None
        seeing = perception_pipeline(pipe, cfg.n_agents, cfg.max_detections)
        perceived = [perceive_sequence(seeing, simulate_robots(cfg, frames, s), camera, min_iou, min_visible=0.5,
                                       advance=advance) for s in sequence_seeds([setup], sequences, seed)]
        seconds = sum(p.seconds for p in perceived)
        n_det = sum(len(d) for p in perceived for d in p.detections)
        matched = sum(p.matched for p in perceived)
        errors = [e for p in perceived for e in p.heading_errors]
        perception.append({
            "Setup": preset_label(setup), "Frames": sequences * frames,
            "Recall": round(matched / max(sum(p.robots for p in perceived), 1), 3),
            "Precision": round(sum(int((t >= 0).sum()) for p in perceived for t in p.truth) / max(n_det, 1), 3),
            "Heading error (deg)": round(float(np.mean(errors)), 1) if errors else float("nan"),
            "Perception frames/s": round(sequences * frames / seconds, 1) if seconds > 0 else float("inf"),
        })
        for name in identifiers:
            pix = score_pixels(name, perceived, pipe, camera, weights)
            sim = score_simulated(name, perceived, camera, weights)
            rows.append({
                "Setup": preset_label(setup), "Identifier": name, "Pixels (%)": round(100 * pix.success, 2),
                "Simulated (%)": round(100 * sim.success, 2), "Gap (pp)": round(100 * (pix.success - sim.success), 2),
                "Pixels robots (%)": round(100 * pix.robot_success, 2),
                "Sim robots (%)": round(100 * sim.robot_success, 2),
                "Pixels loc. (m)": round(pix.loc_error, 3), "Simulated loc. (m)": round(sim.loc_error, 3),
                "Pixel dets": pix.detections, "Sim dets": sim.detections, "Frames/s": round(pix.fps, 1),
            })
    return rows, perception


PIXEL_KEYS = {"Pixels (%)": "success_rate_pixels", "Simulated (%)": "success_rate_simulated",
              "Pixels robots (%)": "success_rate_robots_pixels", "Sim robots (%)": "success_rate_robots_simulated",
              "Pixels loc. (m)": "localisation_error_pixels", "Simulated loc. (m)": "localisation_error_simulated",
              "Pixel dets": "detections_pixels", "Sim dets": "detections_simulated"}


def pixels_results(rows: list[dict[str, Any]], perception: list[dict[str, Any]], setups: list[str],
                   sequences: int, frames: int, seed: int = DEFAULT_SEED, command: str = "",
                   options: dict[str, Any] | None = None) -> Results:
    """The tables of :func:`pixels_table` as a results document: ``identification`` (:data:`PIXEL_KEYS`; fractions,
    metres) and ``perception`` (tracker ``perception``)."""
    doc, names = setup_results("bench pixels", setups, sequences, frames, seed, command, options)
    add_printed_rows(doc, "identification", rows, tracker_key="Identifier", datasets=names, rename=PIXEL_KEYS)
    add_printed_rows(doc, "perception", perception, tracker="perception", datasets=names)
    return doc


__all__ = ["DEFAULT_SEED", "PERCEPTION_COLUMNS", "PIXEL_COLUMNS", "PIXEL_KEYS", "IdentScore", "PerceivedSequence",
           "match_truth", "perceive_sequence", "perception_pipeline", "pixels_results", "pixels_table",
           "robot_success_rate", "score_pixels", "score_simulated"]
