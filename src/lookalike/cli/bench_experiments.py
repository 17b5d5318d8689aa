"""Seed A's control and recovery experiments as ``lookalike bench`` commands.

``bench shuffle``: the identifiers on frames fed in random order. A method that really uses the
sequence (motion, report history) must collapse; one that only matched single frames would not.

``bench recovery``: the heading reports of two robots are swapped for ``--swap-s`` seconds, so
the identifiers learn wrong identities, then restored. The two are, per sequence, the robots
detected most often from the swap's start to 3 s after the restore (so that there is something to
recover). Reported: the success rate on those two robots' detections while swapped (without the
swap, for comparison), and how long after the restore their success rate over a one-second window
is back within 5 points of the same run without the swap.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import typer

from lookalike.cli.app import fail
from lookalike.cli.bench import _build, _split, bench_app, print_rows, write_rows
from lookalike.eval import identification_success_rate
from lookalike.sim import PRESET_NAMES, preset, preset_label, simulate_robots
from lookalike.trackers.identity import labels_from_tracks
from lookalike.types import Beacons, Frame

DEFAULT_SEED = 950_000  # disjoint from training (>= 1.9e9), tuning (< 100000) and bench ident (900000+)


def _labels(name, sequence, frames: list[Frame]) -> list[np.ndarray]:
    tracker = _build(name, sequence)
    return [labels_from_tracks(len(f.detections), tracker.update(f)) for f in frames]


def _reindex(frames: list[Frame]) -> list[Frame]:
    """Frames renumbered and re-timed in their new order (time must not run backwards)."""
    times = np.sort([f.time for f in frames])
    dt = float(np.median(np.diff(times))) if len(frames) > 1 else 1 / 30
    return [Frame(index=k, time=k * dt, detections=f.detections, beacons=_retime(f.beacons, k * dt))
            for k, f in enumerate(frames)]


def _retime(beacons: Beacons, t: float) -> Beacons:
    n = len(beacons)
    return Beacons(agent_id=beacons.agent_id, t_sent=np.full(n, t), t_received=np.full(n, t), heading=beacons.heading)


def _swap_reports(frames: list[Frame], start_s: float, stop_s: float, pair: tuple[int, int] = (0, 1)) -> list[Frame]:
    """Frames whose reports from the robots ``pair`` sent in ``[start_s, stop_s)`` carry each other's id."""
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


@bench_app.command("shuffle")
def shuffle(
    setups: list[str] = typer.Option(list(PRESET_NAMES), "--setups", help="Presets (comma-separated or repeated)."),
    trackers: list[str] = typer.Option(["jpda", "lstm"], "--trackers", help="Identifiers to compare."),
    sequences: int = typer.Option(3, min=1, help="Test sequences per set-up."),
    frames: int = typer.Option(1000, min=2, help="Frames per sequence."),
    seed: int = typer.Option(DEFAULT_SEED, help="Base seed of the test sequences."),
    json_path: str = typer.Option(None, "--json", help="Also write the rows as JSON."),
    csv_path: str = typer.Option(None, "--csv", help="Also write the rows as CSV."),
) -> None:
    """Control experiment: success rate on frames in order and in random order."""
    rows = []
    for setup in _split(setups):
        try:
            cfg = preset(setup)
        except ValueError as exc:
            fail(str(exc))
        for name in _split(trackers):
            ordered, shuffled, truth_o, truth_s = [], [], [], []
            for k in range(sequences):
                seq = simulate_robots(cfg, frames, seed + 1000 * PRESET_NAMES.index(setup) + k)
                fs = list(seq.frames())
                truth = seq.true_labels()
                perm = np.random.default_rng(seed + k).permutation(len(fs))
                ordered += _labels(name, seq, fs)
                truth_o += truth
                shuffled += _labels(name, seq, _reindex([fs[i] for i in perm]))
                truth_s += [truth[i] for i in perm]
            rows.append({
                "Setup": preset_label(setup), "Tracker": name,
                "In order (%)": round(100 * identification_success_rate(ordered, truth_o), 2),
                "Random order (%)": round(100 * identification_success_rate(shuffled, truth_s), 2),
            })
    print_rows("Control: frames in random order", rows)
    write_rows(rows, _path(json_path), _path(csv_path))


@bench_app.command("recovery")
def recovery(
    setups: list[str] = typer.Option(list(PRESET_NAMES), "--setups", help="Presets (comma-separated or repeated)."),
    trackers: list[str] = typer.Option(["kalman_ha2", "jpda", "lstm"], "--trackers", help="Identifiers."),
    sequences: int = typer.Option(3, min=1, help="Test sequences per set-up."),
    frames: int = typer.Option(900, min=300, help="Frames per sequence."),
    swap_at_s: float = typer.Option(5.0, help="When the swap starts, seconds."),
    swap_s: float = typer.Option(10.0, help="How long reports stay swapped, seconds."),
    seed: int = typer.Option(DEFAULT_SEED, help="Base seed of the test sequences."),
    json_path: str = typer.Option(None, "--json", help="Also write the rows as JSON."),
    csv_path: str = typer.Option(None, "--csv", help="Also write the rows as CSV."),
) -> None:
    """Recovery experiment: swap two robots' reports, restore them, time the return to normal."""
    rows = []
    for setup in _split(setups):
        try:
            cfg = preset(setup)
        except ValueError as exc:
            fail(str(exc))
        rate = cfg.frame_rate_hz
        for name in _split(trackers):
            times, during_swapped, during_clean = [], [], []
            for k in range(sequences):
                seq = simulate_robots(cfg, frames, seed + 1000 * PRESET_NAMES.index(setup) + k)
                fs = list(seq.frames())
                truth = seq.true_labels()
                start, restore = int(swap_at_s * rate), int(np.ceil((swap_at_s + swap_s) * rate))
                pair = _most_seen_pair(truth[start : restore + int(3 * rate)], cfg.n_agents)
                clean = _pair_hits(_labels(name, seq, fs), truth, pair)
                swapped_frames = _swap_reports(fs, swap_at_s, swap_at_s + swap_s, pair)
                swapped = _pair_hits(_labels(name, seq, swapped_frames), truth, pair)
                during_swapped.append(_rate(swapped[start:restore]))
                during_clean.append(_rate(clean[start:restore]))
                times.append(_recovery_s(clean, swapped, restore, int(rate), rate))
            rows.append({
                "Setup": preset_label(setup), "Tracker": name,
                "Swapped robots while swapped (%)": round(100 * float(np.mean(during_swapped)), 1),
                "Same without swap (%)": round(100 * float(np.mean(during_clean)), 1),
                "Recovery, mean (s)": round(float(np.mean(times)), 2),
                "Recovery, worst (s)": round(float(np.max(times)), 2),
            })
    print_rows(f"Recovery after {swap_s:g} s of swapped reports", rows)
    write_rows(rows, _path(json_path), _path(csv_path))


def _most_seen_pair(truth: list[np.ndarray], n_agents: int) -> tuple[int, int]:
    """The two robots with the most detections in ``truth`` (ties: lower ids)."""
    counts = np.bincount(np.concatenate([t[t >= 0] for t in truth] + [np.zeros(0, int)]), minlength=n_agents)
    a, b = np.argsort(-counts, kind="stable")[:2]
    return int(a), int(b)


def _pair_hits(predicted: list[np.ndarray], truth: list[np.ndarray], pair: tuple[int, int] = (0, 1)) -> list[tuple[int, int]]:
    """Per frame: (correct, total) labels of the detections that truly are one of the robots ``pair``."""
    out = []
    for p, t in zip(predicted, truth):
        mine = (t == pair[0]) | (t == pair[1])
        out.append((int((p[mine] == t[mine]).sum()), int(mine.sum())))
    return out


def _rate(hits: list[tuple[int, int]]) -> float:
    total = sum(n for _, n in hits)
    return sum(c for c, _ in hits) / total if total else float("nan")


def _recovery_s(clean, swapped, restore: int, window: int, rate: float, tolerance: float = 0.05) -> float:
    """Seconds from ``restore`` until the swapped run's success on the swapped pair over ``window``
    frames is within ``tolerance`` of the clean run's over the same frames (inf: never)."""
    for t in range(restore, len(clean) - window + 1):
        a, b = _rate(swapped[t : t + window]), _rate(clean[t : t + window])
        if np.isfinite(a) and np.isfinite(b) and a >= b - tolerance:
            return (t - restore) / rate
    return float("inf")


def _path(value: str | None) -> Path | None:
    return Path(value) if value else None
