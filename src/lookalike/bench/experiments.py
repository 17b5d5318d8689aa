"""Farazi and Behnke's control experiments: ``bench shuffle`` (frames in random order) and ``bench recovery`` (the
reports of the two robots seen most swapped for ``swap_s`` seconds, then restored: success while swapped and after,
and seconds until the one-second success rate is back within 5 points of the unswapped run)."""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from functools import partial
from typing import Any, NamedTuple

import numpy as np

from lookalike.bench.ident import identify, sequence_seeds, setup_results
from lookalike.bench.paired import Comparison, add_comparisons, compare_to_first, mean_difference
from lookalike.bench.progress import ProgressFactory, no_progress
from lookalike.eval import identification_success_rate
from lookalike.io.results import Results, add_printed_rows
from lookalike.sim import RobotSequence, preset, preset_label, simulate_robots
from lookalike.types import Beacons, Frame

DEFAULT_SEED = 950_000  # disjoint from training (>= 1.9e9), tuning (< 100000) and bench ident (900000+)
Hits = list[tuple[int, int]]


def reindex(frames: list[Frame]) -> list[Frame]:
    """Frames renumbered and re-timed in their new order (time must not run backwards)."""
    times = np.sort([f.time for f in frames])
    dt = float(np.median(np.diff(times))) if len(frames) > 1 else 1 / 30
    return [Frame(index=k, time=k * dt, detections=f.detections, beacons=_retime(f.beacons, k * dt))
            for k, f in enumerate(frames)]


def _retime(beacons: Beacons, t: float) -> Beacons:
    n = len(beacons)
    return Beacons(agent_id=beacons.agent_id, t_sent=np.full(n, t), t_received=np.full(n, t), heading=beacons.heading)


def swap_reports(frames: list[Frame], start_s: float, stop_s: float, pair: tuple[int, int] = (0, 1)) -> list[Frame]:
    """Frames whose reports from ``pair`` sent in ``[start_s, stop_s)`` carry each other's id."""
    out = []
    for f in frames:
        b = f.beacons
        ids = b.agent_id.copy()
        window = (b.t_sent >= start_s) & (b.t_sent < stop_s)
        ids[window & (b.agent_id == pair[0])] = pair[1]
        ids[window & (b.agent_id == pair[1])] = pair[0]
        swapped = Beacons(agent_id=ids, t_sent=b.t_sent, t_received=b.t_received, heading=b.heading)
        out.append(Frame(index=f.index, time=f.time, detections=f.detections, beacons=swapped))
    return out


def most_seen_pair(truth: list[np.ndarray], n_agents: int) -> tuple[int, int]:
    """The two robots with the most detections in ``truth`` (ties: lower ids)."""
    counts = np.bincount(np.concatenate([t[t >= 0] for t in truth] + [np.zeros(0, int)]), minlength=n_agents)
    a, b = np.argsort(-counts, kind="stable")[:2]
    return int(a), int(b)


def pair_hits(predicted: list[np.ndarray], truth: list[np.ndarray], pair: tuple[int, int] = (0, 1)) -> Hits:
    """Per frame: (correct, total) labels of the detections that truly are one of the robots ``pair``."""
    out = []
    for p, t in zip(predicted, truth):
        mine = (t == pair[0]) | (t == pair[1])
        out.append((int((p[mine] == t[mine]).sum()), int(mine.sum())))
    return out


def hit_rate(hits: Hits) -> float:
    """Correct / total over ``hits`` (NaN when there is nothing)."""
    total = sum(n for _, n in hits)
    return sum(c for c, _ in hits) / total if total else float("nan")


def recovery_s(clean: Hits, swapped: Hits, restore: int, window: int, rate: float, tolerance: float = 0.05) -> float:
    """Seconds from ``restore`` until the swapped run's ``window``-frame success nears the clean one (inf: never)."""
    for t in range(restore, len(clean) - window + 1):
        a, b = hit_rate(swapped[t : t + window]), hit_rate(clean[t : t + window])
        if np.isfinite(a) and np.isfinite(b) and a >= b - tolerance:
            return (t - restore) / rate
    return float("inf")


def _sequences(setup: str, sequences: int, frames: int, seed: int) -> list[RobotSequence]:
    return [simulate_robots(preset(setup), frames, s) for s in sequence_seeds([setup], sequences, seed)]


def shuffle_rows(setups: Sequence[str], trackers: Sequence[str], sequences: int, frames: int,
                 seed: int = DEFAULT_SEED, progress: ProgressFactory = no_progress) -> list[dict[str, Any]]:
    """Per set-up and identifier: success rate (%) on frames in order and in random order."""
    rows = []
    for setup in setups:
        preset(setup)  # an unknown set-up fails before any work
    step = progress("bench shuffle", len(setups) * len(trackers))
    for setup in setups:
        for name in trackers:
            ordered, shuffled, truth_o, truth_s = [], [], [], []
            for k, seq in enumerate(_sequences(setup, sequences, frames, seed)):
                fs = list(seq.frames())
                truth = seq.true_labels()
                perm = np.random.default_rng(seed + k).permutation(len(fs))
                ordered += identify(name, seq, fs)
                truth_o += truth
                shuffled += identify(name, seq, reindex([fs[i] for i in perm]))
                truth_s += [truth[i] for i in perm]
            rows.append({
                "Setup": preset_label(setup), "Tracker": name,
                "In order (%)": round(100 * identification_success_rate(ordered, truth_o), 2),
                "Random order (%)": round(100 * identification_success_rate(shuffled, truth_s), 2),
            })
            step()
    return rows


class SwapRun(NamedTuple):
    """One sequence of :func:`swap_recovery`: success on the swapped pair (fractions; NaN: unseen) while swapped and
    :data:`AFTER_S` seconds after the restore, each also without the swap, and the recovery seconds (inf: never)."""

    while_swapped: float
    clean_while_swapped: float
    recovery_s: float
    after_restore: float
    clean_after_restore: float


AFTER_S = 3.0  # seconds after the restore that pick the pair and give the success after the restore
APART_RAD = 0.2  # restore_gap from which the pair's reports tell the two robots apart (about 6 report noises)


def swap_frames(rate_hz: float, swap_at_s: float, swap_s: float) -> tuple[int, int, int]:
    """Frame indices of the swap's start, of the restore and :data:`AFTER_S` seconds after it."""
    restore = int(np.ceil((swap_at_s + swap_s) * rate_hz))
    return int(swap_at_s * rate_hz), restore, restore + int(AFTER_S * rate_hz)


def longest_recovery_s(frames: int, rate_hz: float, swap_at_s: float, swap_s: float) -> float:
    """The longest recovery (s) measurable in ``frames`` frames: from the restore to the last one-second window."""
    return (frames - int(rate_hz) - swap_frames(rate_hz, swap_at_s, swap_s)[1]) / rate_hz


def swapped_pair(sequence: RobotSequence, swap_at_s: float, swap_s: float) -> tuple[int, int]:
    """The two robots seen most from ``swap_at_s`` to :data:`AFTER_S` s after the restore: those swapped."""
    start, _, after = swap_frames(sequence.config.frame_rate_hz, swap_at_s, swap_s)
    return most_seen_pair(sequence.true_labels()[start:after], sequence.config.n_agents)


def swap_recovery(labels: Callable[[RobotSequence, list[Frame]], list[np.ndarray]], seq: RobotSequence,
                  swap_at_s: float, swap_s: float) -> SwapRun:
    """:class:`SwapRun` of ``seq`` with :func:`swapped_pair`'s reports swapped from ``swap_at_s`` for ``swap_s``
    seconds; ``labels(seq, frames)``: an identifier's per-frame labels."""
    rate = seq.config.frame_rate_hz
    fs = list(seq.frames())
    truth = seq.true_labels()
    start, restore, after = swap_frames(rate, swap_at_s, swap_s)
    pair = swapped_pair(seq, swap_at_s, swap_s)
    clean = pair_hits(labels(seq, fs), truth, pair)
    swapped = pair_hits(labels(seq, swap_reports(fs, swap_at_s, swap_at_s + swap_s, pair)), truth, pair)
    return SwapRun(hit_rate(swapped[start:restore]), hit_rate(clean[start:restore]),
                   recovery_s(clean, swapped, restore, int(rate), rate),
                   hit_rate(swapped[restore:after]), hit_rate(clean[restore:after]))


def measurable(sequence: RobotSequence, swap_at_s: float = 5.0, swap_s: float = 10.0) -> bool:
    """Whether :func:`swapped_pair` has a detection while swapped and one after the restore (from the truth)."""
    rate = sequence.config.frame_rate_hz
    truth = sequence.true_labels()
    start, restore, _ = swap_frames(rate, swap_at_s, swap_s)
    a, b = swapped_pair(sequence, swap_at_s, swap_s)

    def seen(frames: list[np.ndarray]) -> bool:
        return any(((t == a) | (t == b)).any() for t in frames)

    return seen(truth[start:restore]) and seen(truth[restore:])


def measured_sequences(setup: str, sequences: int, frames: int, seed: int, swap_at_s: float = 5.0,
                       swap_s: float = 10.0) -> list[RobotSequence]:
    """The :func:`measurable` ones of set-up ``setup``'s ``sequences`` sequences from ``seed``, in order."""
    return [q for q in _sequences(setup, sequences, frames, seed) if measurable(q, swap_at_s, swap_s)]


def _seen_mean(rates: np.ndarray) -> float:
    """Mean of the sequences' success rates where the pair was seen (NaN: nowhere)."""
    seen = rates[np.isfinite(rates)]
    return float(seen.mean()) if seen.size else float("nan")


def recovery_runs(setups: Sequence[str], trackers: Sequence[str], sequences: int, frames: int, swap_at_s: float,
                  swap_s: float, seed: int = DEFAULT_SEED, progress: ProgressFactory = no_progress,
                  options: Mapping[str, Mapping[str, Any]] | None = None
                  ) -> tuple[list[dict[str, Any]], dict[tuple[str, str], list[float]]]:
    """Rows per set-up and identifier: success on the swapped pair while swapped (and without the swap), the mean
    and worst recovery time (s) over the :func:`measurable` sequences, and their count; and per (set-up, identifier)
    each sequence's recovery seconds (inf: never). ``options``: identifier -> its parameters."""
    rows, runs = swap_runs(setups, trackers, sequences, frames, swap_at_s, swap_s, seed, progress, options)
    recovery = SwapRun._fields.index("recovery_s")
    return rows, {key: [float(v) for v in run[:, recovery]] for key, run in runs.items()}


def swap_runs(setups: Sequence[str], trackers: Sequence[str], sequences: int, frames: int, swap_at_s: float,
              swap_s: float, seed: int = DEFAULT_SEED, progress: ProgressFactory = no_progress,
              options: Mapping[str, Mapping[str, Any]] | None = None
              ) -> tuple[list[dict[str, Any]], dict[tuple[str, str], np.ndarray]]:
    """:func:`recovery_runs`' rows and per (set-up, identifier) an array of :class:`SwapRun` (sequences x fields)."""
    rows = []
    runs_of: dict[tuple[str, str], np.ndarray] = {}
    for setup in setups:
        preset(setup)
    step = progress("bench recovery", len(setups) * len(trackers))
    for setup in setups:
        measured = measured_sequences(setup, sequences, frames, seed, swap_at_s, swap_s)
        apart = np.array([restore_gap(q, swap_at_s, swap_s) >= APART_RAD for q in measured], dtype=bool)
        width = len(SwapRun._fields)
        for name in trackers:
            labels = partial(identify, name, options=(options or {}).get(name))
            runs = np.array([swap_recovery(labels, seq, swap_at_s, swap_s) for seq in measured]).reshape(-1, width)
            runs_of[(setup, name)] = runs
            if not len(runs):  # nothing measurable: NaN figures, said by the count
                runs = np.full((1, width), np.nan)
            run = dict(zip(SwapRun._fields, runs.T))  # field -> its value in each sequence
            rows.append({
                "Setup": preset_label(setup), "Tracker": name,
                "Swapped robots while swapped (%)": round(100 * float(np.mean(run["while_swapped"])), 1),
                "Same without swap (%)": round(100 * float(np.mean(run["clean_while_swapped"])), 1),
                "After the restore, 3 s (%)": round(100 * _seen_mean(run["after_restore"]), 1),
                "Same without swap, after (%)": round(100 * _seen_mean(run["clean_after_restore"]), 1),
                "Recovery, mean (s)": round(float(np.mean(run["recovery_s"])), 2),
                "Recovery, worst (s)": round(float(np.max(run["recovery_s"])), 2),
                "Sequences measured": len(measured),
                f"Recovery, reports >= {APART_RAD:g} rad apart, mean (s)": round(
                    float(np.mean(run["recovery_s"][apart])) if apart.any() else float("nan"), 2),
                f"Sequences with reports >= {APART_RAD:g} rad apart": int(apart.sum()),
            })
            step()
    return rows, runs_of


def restore_gap(sequence: RobotSequence, swap_at_s: float = 5.0, swap_s: float = 10.0, window_s: float = 1.0) -> float:
    """How far apart (rad, 0 to π) the circular means of :func:`swapped_pair`'s own reports sent in the ``window_s``
    seconds from the restore are (NaN: either sent none)."""
    pair = swapped_pair(sequence, swap_at_s, swap_s)
    restore_s = swap_at_s + swap_s
    sums, counts = np.zeros(2, dtype=complex), np.zeros(2, dtype=int)
    for f in sequence.frames():
        b = f.beacons
        window = (b.t_sent >= restore_s) & (b.t_sent < restore_s + window_s)
        for i, agent in enumerate(pair):
            mine = window & (b.agent_id == agent)
            sums[i] += np.exp(1j * b.heading[mine]).sum()
            counts[i] += int(mine.sum())
    if not counts.all():
        return float("nan")
    return float(abs(np.angle(sums[0] / sums[1])))


def recovery_differences(seconds: dict[tuple[str, str], list[float]], setups: Sequence[str],
                         trackers: Sequence[str]) -> list[Comparison]:
    """Each identifier's mean recovery seconds minus the first's (:func:`~lookalike.bench.paired.mean_difference`)."""
    return compare_to_first(seconds, setups, trackers, mean_difference, preset_label)


EXPERIMENT_KEYS = {"In order (%)": "success_rate_in_order", "Random order (%)": "success_rate_random_order",
                   "Swapped robots while swapped (%)": "success_rate_while_swapped",
                   "Same without swap (%)": "success_rate_without_swap",
                   "After the restore, 3 s (%)": "success_rate_after_restore",
                   "Same without swap, after (%)": "success_rate_after_restore_without_swap",
                   "Sequences measured": "sequences_measured",
                   f"Recovery, reports >= {APART_RAD:g} rad apart, mean (s)": "recovery_mean_apart_s",
                   f"Sequences with reports >= {APART_RAD:g} rad apart": "sequences_apart"}


def experiment_results(kind: str, rows: list[dict[str, Any]], setups: Sequence[str], sequences: int, frames: int,
                       seed: int = DEFAULT_SEED, command: str = "", options: dict[str, Any] | None = None,
                       differences: Sequence[Comparison] = ()) -> Results:
    """Rows of :func:`shuffle_rows` or :func:`recovery_runs` as a results document (table ``kind``; success rates as
    fractions, seconds, ``null`` when never); ``differences`` go in table ``<kind>_difference`` (seconds)."""
    doc, names = setup_results(f"bench {kind}", setups, sequences, frames, seed, command, options)
    add_printed_rows(doc, kind, rows, datasets=names, rename=EXPERIMENT_KEYS)
    add_comparisons(doc, f"{kind}_difference", differences, "recovery_mean_s", suffix="_s")
    return doc


__all__ = ["AFTER_S", "APART_RAD", "DEFAULT_SEED", "EXPERIMENT_KEYS", "SwapRun", "experiment_results", "hit_rate",
           "longest_recovery_s", "measured_sequences", "most_seen_pair", "pair_hits", "recovery_differences",
           "recovery_runs", "recovery_s", "reindex", "restore_gap", "shuffle_rows", "swap_frames",
           "swap_recovery", "swap_reports", "swap_runs", "swapped_pair"]
