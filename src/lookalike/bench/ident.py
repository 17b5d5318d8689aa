"""Farazi and Behnke's Table I (``lookalike bench ident``): per set-up and identifier, on the same simulated sequences
(seeds ``seed + 1000·setup + sequence``), success rate (a false positive labelled as such is correct), localisation
error (m, while in view) and frames/s."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from lookalike.bench.ident_paper import resolve_identifier
from lookalike.bench.paired import Comparison, PairedDifference, add_comparisons, compare_to_first, rate_difference
from lookalike.bench.progress import ProgressFactory, Step, no_progress
from lookalike.eval import identification_counts, identification_success_rate, localisation_error
from lookalike.io.results import Results, percent_row_metrics
from lookalike.loop import RunStats, run, warm_up
from lookalike.sim import DEFAULT_NOISE, RobotSequence, preset, preset_label, simulate_robots
from lookalike.sim.presets import team_index
from lookalike.trackers import make_tracker, tracker_parameters
from lookalike.trackers.lstm.weights import shipped_weights_path
from lookalike.trackers.parts.identity import agent_positions, labels_from_tracks
from lookalike.trackers.parts.weights_io import CheckpointError
from lookalike.types import Frame

# lstm: the paper's method, our inputs; lstm-paper: the paper's protocol; set: any team size
IDENT_TRACKERS = ("lstm", "lstm-paper", "set", "kalman_ha", "kalman_ha2", "jpda")
IDENT_COLUMNS = ("Setup", "Tracker", "Success rate (%)", "Localisation error (m)", "Frames/s", "Detections")
DEFAULT_SEED = 900_000
NOT_TRAINED = "not trained"  # the cells of an LSTM row whose shipped weights do not exist for the set-up
SequenceCounts = dict[tuple[str, str], list[tuple[int, int]]]  # (preset, identifier) -> [(correct, detections)]


def uses_weights(name: str) -> bool:
    """Whether identifier ``name`` runs our protocol's LSTM (the rows that ``weights=`` replaces)."""
    base, extra = resolve_identifier(name)
    return base == "lstm" and extra.get("protocol", "ours") == "ours"


def check_weights(weights: str | None, setups: Sequence[str], trackers: Sequence[str]) -> None:
    """Refuse exported LSTM ``weights`` for more than one set-up, or when no identifier of ``trackers`` uses them
    (:func:`uses_weights`): they would be ignored."""
    if not weights:
        return
    if len(setups) != 1:
        raise ValueError(f"weights: {weights} are for one set-up; got {len(setups)} set-ups")
    if not any(uses_weights(t) for t in trackers):
        raise ValueError(f"weights: {weights} are for the lstm and lstm-lowpass rows; none of {', '.join(trackers)} "
                         "uses them")


def weights_missing(name: str, n_agents: int, n_slots: int, weights: str | None = None) -> bool:
    """Whether identifier ``name`` needs shipped LSTM weights for N, M and none ship (``weights`` given: never)."""
    base, extra = resolve_identifier(name)
    if base != "lstm" or extra.get("weights") or (weights and uses_weights(name)):
        return False
    try:
        shipped_weights_path(n_agents, n_slots, "lstm_paper" if extra.get("protocol") == "paper" else "lstm")
    except CheckpointError:
        return True
    return False


def build_identifier(name: str, sequence: RobotSequence, weights: str | None = None,
                     options: Mapping[str, Any] | None = None) -> Any:
    """Tracker or variant ``name`` for the sequence's N (and M); ``weights``: exported .npz for our protocol's LSTM
    rows; ``options``: more parameters (overriding the variant's)."""
    base, extra = resolve_identifier(name)
    extra.update(options or {})
    if weights and uses_weights(name):
        extra["weights"] = weights
    known = {p.name for p in tracker_parameters(base)}
    cfg = sequence.config
    params = {k: v for k, v in (("n_agents", cfg.n_agents), ("n_slots", cfg.max_detections)) if k in known}
    return make_tracker(base, **params, **extra)


def identify(name: str, sequence: RobotSequence, frames: Sequence[Frame] | None = None,
             stats: RunStats | None = None, options: Mapping[str, Any] | None = None) -> list[np.ndarray]:
    """Per frame, each detection's agent label (-1: false positive) from identifier ``name``."""
    labels: list[np.ndarray] = []
    tracker = build_identifier(name, sequence, options=options)
    run(tracker, sequence.frames() if frames is None else frames,
        lambda f, tracks: labels.append(labels_from_tracks(len(f.detections), tracks)), stats=stats)
    return labels


def run_labels(tracker: Any, frames: Sequence[Frame], n_agents: int, stats: RunStats | None = None
               ) -> tuple[list[np.ndarray], np.ndarray]:
    """Per frame, each detection's label, and ``(frames, n_agents, 2)`` agent positions (m) of ``tracker``."""
    labels: list[np.ndarray] = []
    positions = np.full((len(frames), n_agents, 2), np.nan)

    def sink(frame: Frame, tracks: Any) -> None:
        positions[len(labels)] = agent_positions(tracks, n_agents)
        labels.append(labels_from_tracks(len(frame.detections), tracks))

    run(tracker, frames, sink, stats=stats)
    return labels, positions


def setup_results(kind: str, setups: Sequence[str], sequences: int, frames: int, seed: int, command: str,
                  options: Mapping[str, Any] | None = None) -> tuple[Results, dict[str, str]]:
    """An empty results document of a bench over set-ups, and the set-ups by printed label."""
    doc = Results(kind, command=command, seeds=sequence_seeds(list(setups), sequences, seed),
                  sequences=len(setups) * sequences, frames=len(setups) * sequences * frames,
                  options={"setups": list(setups), "sequences_per_setup": sequences, "frames_per_sequence": frames,
                           "seed": seed, **(options or {})})
    return doc, {preset_label(s): s for s in setups}


def run_identifier(name: str, sequences: list[RobotSequence], step: Step | None = None,
                   weights: str | None = None) -> dict[str, float]:
    """Success rate, localisation error, frames/s and detection count of tracker ``name`` (``step()`` per sequence)."""
    return run_identifier_by_sequence(name, sequences, step, weights)[0]


def run_identifier_by_sequence(name: str, sequences: list[RobotSequence], step: Step | None = None,
                               weights: str | None = None) -> tuple[dict[str, float], list[tuple[int, int]]]:
    """:func:`run_identifier`'s figures and per sequence (correct labels, detections)."""
    predicted: list[np.ndarray] = []
    truth: list[np.ndarray] = []
    est, true_pos = [], []
    counts: list[tuple[int, int]] = []
    stats = RunStats()
    if sequences:  # frames/s without the first frames' one-off costs (imports, compiles)
        warm_up(lambda: build_identifier(name, sequences[0], weights), sequences[0].frames())
    for seq in sequences:
        labels, positions = run_labels(build_identifier(name, seq, weights), list(seq.frames()), seq.config.n_agents,
                                       stats)
        counts.append(identification_counts(labels, seq.true_labels()))
        predicted += labels
        truth += seq.true_labels()
        est.append(positions)
        true_pos.append(seq.true_positions_visible())
        if step is not None:
            step()
    return {
        "success": identification_success_rate(predicted, truth),
        "loc_error": localisation_error(np.concatenate(est), np.concatenate(true_pos)),
        "fps": stats.fps,
        "detections": float(sum(len(p) for p in predicted)),
    }, counts


def sequence_seeds(setups: list[str], sequences: int, seed: int = DEFAULT_SEED) -> list[int]:
    """Seeds of the test sequences, set-up after set-up (``seed + 1000·team_index + sequence``)."""
    return [seed + 1000 * team_index(s) + k for s in setups for k in range(sequences)]


def ident_table(setups: list[str], trackers: list[str], sequences: int, frames: int,
                seed: int = DEFAULT_SEED, noise: str = DEFAULT_NOISE,
                progress: ProgressFactory = no_progress, weights: str | None = None) -> list[dict[str, Any]]:
    """Rows (:data:`IDENT_COLUMNS`) per set-up and tracker on the same sequences, position noise ``noise``
    (``"paper"`` or ``"ours"``); ``weights``: exported .npz for our protocol's LSTM rows (one set-up only)."""
    return ident_runs(setups, trackers, sequences, frames, seed, noise, progress, weights)[0]


def ident_runs(setups: list[str], trackers: list[str], sequences: int, frames: int,
               seed: int = DEFAULT_SEED, noise: str = DEFAULT_NOISE, progress: ProgressFactory = no_progress,
               weights: str | None = None) -> tuple[list[dict[str, Any]], SequenceCounts]:
    """:func:`ident_table`'s rows and per (set-up, identifier) that ran, per-sequence (correct labels, detections)."""
    check_weights(weights, setups, trackers)
    rows = []
    counts: SequenceCounts = {}
    step = progress("bench ident", len(setups) * len(trackers) * sequences)
    for setup in setups:
        cfg = preset(setup, noise)
        seqs = [simulate_robots(cfg, frames, s) for s in sequence_seeds([setup], sequences, seed)]
        for name in trackers:
            if weights_missing(name, cfg.n_agents, cfg.max_detections, weights):
                rows.append({"Setup": preset_label(setup), "Tracker": name, "Success rate (%)": NOT_TRAINED,
                             "Localisation error (m)": NOT_TRAINED, "Frames/s": NOT_TRAINED, "Detections": 0})
                for _ in seqs:
                    step()
                continue
            r, counts[(setup, name)] = run_identifier_by_sequence(name, seqs, step, weights)
            rows.append({
                "Setup": preset_label(setup), "Tracker": name, "Success rate (%)": round(100 * r["success"], 2),
                "Localisation error (m)": round(r["loc_error"], 3), "Frames/s": round(r["fps"], 1),
                "Detections": int(r["detections"]),
            })
    return rows, counts


def ident_differences(counts: SequenceCounts, setups: list[str], trackers: list[str]) -> list[Comparison]:
    """Each identifier's success rate minus the first's (:func:`~lookalike.bench.paired.rate_difference`)."""
    def difference(other: Sequence[tuple[int, int]], base: Sequence[tuple[int, int]]) -> PairedDifference:
        return rate_difference([c for c, _ in other], [c for c, _ in base], [n for _, n in base])

    return compare_to_first(counts, setups, trackers, difference, preset_label)


def ident_results(rows: list[dict[str, Any]], setups: list[str], sequences: int, frames: int,
                  seed: int = DEFAULT_SEED, command: str = "", noise: str = DEFAULT_NOISE,
                  weights: str | None = None, differences: Sequence[Comparison] = ()) -> Results:
    """:func:`ident_table`'s rows as a results document: table ``ident`` (dataset: the preset name) and
    ``differences`` in table ``ident_difference`` (fractions)."""
    doc, names = setup_results("bench ident", setups, sequences, frames, seed, command,
                               {"noise": noise, **({"weights": weights} if weights else {})})
    for r in rows:
        doc.add("ident", dataset=names.get(r["Setup"], r["Setup"]), tracker=r["Tracker"],
                metrics=percent_row_metrics(r, skip=("Setup", "Tracker")))
    add_comparisons(doc, "ident_difference", differences, "success_rate", scale=0.01)
    return doc


__all__ = ["DEFAULT_SEED", "IDENT_COLUMNS", "IDENT_TRACKERS", "NOT_TRAINED", "SequenceCounts", "build_identifier",
           "check_weights", "ident_differences", "ident_results", "ident_runs", "ident_table", "identify",
           "run_identifier", "run_identifier_by_sequence", "run_labels", "sequence_seeds", "setup_results",
           "uses_weights", "weights_missing"]
