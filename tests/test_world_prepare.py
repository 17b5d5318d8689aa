"""``WorldTracker.prepare`` (the next frame's prediction made between frames) changes nothing: the tracks
are bit for bit those of a run without it, whether the frame interval repeats (the prepared state is used)
or not (it is dropped), with the compiled kernels and without them."""

from __future__ import annotations

import dataclasses
from collections.abc import Iterator

import numpy as np
import pytest

import lookalike.trackers.kernels.world as wk
from lookalike.node.teamsim import team_sequence
from lookalike.trackers import make_tracker
from lookalike.types import Frame

FIELDS = ("id", "status", "position", "velocity", "heading", "agent_id", "identity_prob", "detection_index")


@pytest.fixture(autouse=True)
def _default_switch() -> Iterator[None]:
    yield
    wk.use_compiled(None)


def _frames(preset: str, seed: int, jitter: bool) -> tuple[int, list[Frame]]:
    sequence = team_sequence(preset, seed, 3.0, loss=0.2, jitter_s=0.1)
    frames = list(sequence.frames())
    if jitter:  # (frame times off the 30 Hz grid by up to 2 ms: the interval never repeats)
        rng = np.random.default_rng(seed)
        frames = [dataclasses.replace(f, time=f.time + float(rng.uniform(0, 0.002))) if i else f
                  for i, f in enumerate(frames)]
    return sequence.config.n_agents, frames


def _run(name: str, n_agents: int, frames: list[Frame], prepare: bool) -> tuple[list[tuple], int, bool]:
    tracker = make_tracker(name, n_agents=n_agents)
    rows, used, prepared_any = [], 0, False
    for frame in frames:
        ready = dict(tracker._ready)
        out = tracker.update(frame)
        used += bool(rows) and frame.time - rows[-1][0] in ready
        rows.append((frame.time, *(None if getattr(out, f) is None else np.array(getattr(out, f)) for f in FIELDS)))
        if prepare:
            tracker.prepare()
            prepared_any = prepared_any or bool(tracker._ready)
    return rows, used, prepared_any


@pytest.mark.parametrize("compiled", [True, False])
@pytest.mark.parametrize("name", ["kalman_ha", "kalman_ha2", "jpda"])
@pytest.mark.parametrize("jitter", [False, True])
def test_prepared_runs_equal_plain_runs(name: str, compiled: bool, jitter: bool) -> None:
    wk.use_compiled(compiled)
    n_agents, frames = _frames("m10n7", 3, jitter)
    plain, _, _ = _run(name, n_agents, frames, prepare=False)
    prepared, used, prepared_any = _run(name, n_agents, frames, prepare=True)
    assert len(plain) == len(prepared)
    for a, b in zip(plain, prepared):
        for x, y in zip(a[1:], b[1:]):
            assert (x is None) == (y is None)
            if x is not None:
                assert x.dtype == y.dtype and np.array_equal(x, y, equal_nan=x.dtype.kind == "f")
    if name == "jpda" or jitter:  # (JPDA associates its own way; jittered: no interval repeats: nothing prepared)
        assert used == 0 and not prepared_any
    else:
        assert used > 0.8 * len(frames)


def test_prepare_is_dropped_by_reset_and_not_made_without_tracks() -> None:
    n_agents, frames = _frames("m3n2", 2, False)  # a robot detected in 10 of the first 20 frames or more
    tracker = make_tracker("kalman_ha2", n_agents=n_agents)
    tracker.prepare()  # (before any frame: nothing to predict)
    assert not tracker._ready
    for frame in frames[:20]:
        tracker.update(frame)
    tracker.prepare()
    assert 1 <= len(tracker._ready) <= 2  # (the last two distinct intervals, those that came again)
    tracker.reset()
    assert not tracker._ready
