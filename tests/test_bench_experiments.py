import json

import numpy as np
import pytest
from typer.testing import CliRunner

from lookalike.bench.experiments import pair_hits, recovery_s, reindex, swap_reports
from lookalike.cli import app
from lookalike.sim import preset, simulate_robots


def test_swap_exchanges_only_reports_in_the_window():
    seq = simulate_robots(preset("m3n2"), 120, seed=3)
    frames = list(seq.frames())
    swapped = swap_reports(frames, 1.0, 2.0)
    for a, b in zip(frames, swapped):
        inside = (a.beacons.t_sent >= 1.0) & (a.beacons.t_sent < 2.0)
        np.testing.assert_array_equal(b.beacons.agent_id[~inside], a.beacons.agent_id[~inside])
        np.testing.assert_array_equal(b.beacons.agent_id[inside], 1 - a.beacons.agent_id[inside])


def testreindexed_frames_run_forward_in_time():
    seq = simulate_robots(preset("m3n2"), 30, seed=3)
    frames = list(seq.frames())[::-1]
    out = reindex(frames)
    assert [f.index for f in out] == list(range(30))
    assert all(b.time > a.time for a, b in zip(out, out[1:]))
    assert out[0].detections is frames[0].detections


def test_recovery_time_counts_from_the_restore():
    clean = [(2, 2)] * 100
    swapped = [(0, 2)] * 40 + [(2, 2)] * 60
    assert recovery_s(clean, swapped, restore=30, window=10, rate=10.0) == 1.0
    assert recovery_s(clean, [(0, 2)] * 100, restore=30, window=10, rate=10.0) == float("inf")


def testpair_hits_count_only_robots_0_and_1():
    hits = pair_hits([np.array([0, 1, 2, -1]), np.array([1])], [np.array([0, 0, 2, 1]), np.array([1])])
    assert hits == [(1, 3), (1, 1)]


def test_commands_print_and_write_tables(tmp_path):
    runner = CliRunner()
    out = tmp_path / "shuffle.json"
    r = runner.invoke(app, ["bench", "shuffle", "--setups", "m3n2", "--trackers", "kalman_ha2", "--sequences", "1",
                            "--frames", "200", "--json", str(out)])
    assert r.exit_code == 0, r.output
    row = json.loads(out.read_text())["tables"]["shuffle"][0]
    assert row["dataset"] == "m3n2" and row["tracker"] == "kalman_ha2"
    assert row["metrics"]["success_rate_in_order"] > row["metrics"]["success_rate_random_order"]
    out = tmp_path / "recovery.json"
    r = runner.invoke(app, ["bench", "recovery", "--setups", "m3n2", "--trackers", "kalman_ha2", "--sequences", "1",
                            "--frames", "450", "--swap-at-s", "3", "--swap-s", "5", "--json", str(out)])
    assert r.exit_code == 0, r.output
    metrics = json.loads(out.read_text())["tables"]["recovery"][0]["metrics"]
    assert {"recovery_mean_s", "success_rate_after_restore", "success_rate_after_restore_without_swap",
            "recovery_mean_apart_s", "sequences_apart"} <= set(metrics)


def test_success_after_the_restore_says_how_right_an_identifier_is_not_how_it_compares_with_itself():
    from lookalike.bench.experiments import swap_recovery
    from lookalike.sim import preset, simulate_robots

    seq = simulate_robots(preset("m3n2"), 300, 55_005)  # both robots detected in 2-5 s and after 5 s
    original = [f.beacons.agent_id for f in seq.frames()]

    def keeps_the_swap(s, frames):  # right without the swap; with it, the pair's labels exchanged from then on
        truth = s.true_labels()
        moved = [k for k, f in enumerate(frames) if (f.beacons.agent_id != original[k]).any()]
        if not moved:
            return truth
        a, b = sorted(set().union(*(original[k][frames[k].beacons.agent_id != original[k]].tolist() for k in moved)))
        return [t if k < moved[0] else np.where(t == a, b, np.where(t == b, a, t)) for k, t in enumerate(truth)]

    def confused(s, frames):  # every robot labelled as the next one, with or without the swap
        return [np.where(t >= 0, (t + 1) % s.config.n_agents, t) for t in s.true_labels()]

    run = swap_recovery(keeps_the_swap, seq, 2.0, 3.0)
    assert run.while_swapped < 0.1 and run.clean_while_swapped == 1.0  # from the first swapped report on
    assert run.after_restore == 0.0 and run.clean_after_restore == 1.0 and run.recovery_s == float("inf")
    run = swap_recovery(confused, seq, 2.0, 3.0)
    assert run.recovery_s == 0.0 and run.after_restore == 0.0 == run.clean_after_restore


def test_swapped_pair_is_the_two_most_seen_robots():
    from lookalike.bench.experiments import most_seen_pair

    truth = [np.array([2, -1, 3]), np.array([3, 0]), np.array([3, 2, 1])]
    assert most_seen_pair(truth, 4) == (3, 2)
    assert most_seen_pair([np.array([-1])], 3) == (0, 1)


def test_unmeasurable_recoveries_are_those_whose_pair_is_not_seen_both_times():
    from types import SimpleNamespace

    from lookalike.bench.experiments import measurable
    from lookalike.sim import preset, simulate_robots

    seq = simulate_robots(preset("m3n2"), 300, 55_005)  # both robots detected in 2-5 s and after 5 s
    assert measurable(seq, 2.0, 3.0)
    truth = seq.true_labels()
    gone_after = [t if k < 150 else np.full_like(t, -1) for k, t in enumerate(truth)]  # restore at frame 150
    gone_during = [np.full_like(t, -1) if 60 <= k < 150 else t for k, t in enumerate(truth)]
    for labels in (gone_after, gone_during):
        blind = SimpleNamespace(config=seq.config, true_labels=lambda labels=labels: labels)
        assert not measurable(blind, 2.0, 3.0)


def test_recovery_leaves_out_sequences_with_nothing_to_measure(monkeypatch):
    from lookalike.bench import experiments

    real = experiments._sequences
    kept: list[object] = []

    def two_sequences(setup, sequences, frames, seed):
        out = real(setup, sequences, frames, seed)
        kept.append(out[0])
        return out

    monkeypatch.setattr(experiments, "_sequences", two_sequences)
    monkeypatch.setattr(experiments, "measurable", lambda q, *a: q is kept[-1])
    rows, seconds = experiments.recovery_runs(["m3n2"], ["kalman_ha"], 2, 300, 2.0, 3.0)
    assert rows[0]["Sequences measured"] == 1
    assert len(seconds[("m3n2", "kalman_ha")]) == 1
    built: list[dict] = []
    monkeypatch.setattr(experiments, "identify", lambda name, s, fs, options=None: (
        built.append({"name": name, **(options or {})}), [np.full(len(f.detections), -1) for f in fs])[1])
    experiments.recovery_runs(["m3n2"], ["kalman_ha", "lstm"], 2, 300, 2.0, 3.0, options={"kalman_ha": {"gate": 2}})
    assert {"name": "kalman_ha", "gate": 2} in built and {"name": "lstm"} in built  # options go to their identifier
    monkeypatch.setattr(experiments, "measurable", lambda q, *a: False)
    rows, _ = experiments.recovery_runs(["m3n2"], ["kalman_ha"], 2, 300, 2.0, 3.0)
    assert rows[0]["Sequences measured"] == 0 and np.isnan(rows[0]["Recovery, mean (s)"])


def _with_pair_reports(seq, headings):
    """``seq`` whose swapped pair (for a swap from 2 s for 3 s) reports ``headings[i]`` (radians; None: nothing)
    from 5 s on, its other reports as they were."""
    from types import SimpleNamespace

    from lookalike.bench.experiments import swapped_pair
    from lookalike.types import Beacons, Frame

    pair = swapped_pair(seq, 2.0, 3.0)
    frames = []
    for f in seq.frames():
        b = f.beacons
        keep = np.ones(len(b), dtype=bool)
        heading = b.heading.copy()
        for agent, value in zip(pair, headings):
            mine = (b.agent_id == agent) & (b.t_sent >= 5.0)
            if value is None:
                keep &= ~mine
            else:
                heading[mine] = value
        beacons = Beacons(agent_id=b.agent_id[keep], t_sent=b.t_sent[keep], t_received=b.t_received[keep],
                          heading=heading[keep])
        frames.append(Frame(index=f.index, time=f.time, detections=f.detections, beacons=beacons))
    return SimpleNamespace(config=seq.config, true_labels=seq.true_labels, frames=lambda: iter(frames))


def test_restore_gap_is_how_far_apart_the_pairs_reports_are_after_the_restore():
    from lookalike.bench.experiments import restore_gap

    seq = simulate_robots(preset("m3n2"), 300, seed=3)
    assert 0.0 <= restore_gap(seq, 2.0, 3.0) <= np.pi
    assert restore_gap(_with_pair_reports(seq, (1.0, 1.3)), 2.0, 3.0) == pytest.approx(0.3)
    across = _with_pair_reports(seq, (np.pi - 0.05, -np.pi + 0.05))  # either side of ±π: 0.1 rad apart
    assert restore_gap(across, 2.0, 3.0) == pytest.approx(0.1)
    assert np.isnan(restore_gap(_with_pair_reports(seq, (1.0, None)), 2.0, 3.0))  # one of them silent


def test_swap_runs_keep_each_sequences_figures(monkeypatch):
    from lookalike.bench import experiments

    monkeypatch.setattr(experiments, "identify", lambda name, s, fs, options=None: [
        np.where(t >= 0, t, -1) for t in s.true_labels()])  # always right: recovers at once
    rows, runs = experiments.swap_runs(["m3n2"], ["perfect"], 2, 300, 2.0, 3.0)
    run = runs[("m3n2", "perfect")]
    assert run.shape == (rows[0]["Sequences measured"], len(experiments.SwapRun._fields))
    assert (run[:, experiments.SwapRun._fields.index("recovery_s")] == 0.0).all()
    _, seconds = experiments.recovery_runs(["m3n2"], ["perfect"], 2, 300, 2.0, 3.0)
    assert seconds[("m3n2", "perfect")] == [0.0] * len(run)


def test_recovery_rows_give_the_recovery_where_the_reports_tell_the_pair_apart(monkeypatch):
    from lookalike.bench import experiments

    monkeypatch.setattr(experiments, "identify", lambda name, s, fs, options=None: [
        np.where(t >= 0, t, -1) for t in s.true_labels()])
    key, count = "Recovery, reports >= 0.2 rad apart, mean (s)", "Sequences with reports >= 0.2 rad apart"
    monkeypatch.setattr(experiments, "restore_gap", lambda q, *a: 1.0)
    row = experiments.recovery_runs(["m3n2"], ["perfect"], 2, 300, 2.0, 3.0)[0][0]
    assert row[count] == row["Sequences measured"] > 0 and row[key] == row["Recovery, mean (s)"]
    monkeypatch.setattr(experiments, "restore_gap", lambda q, *a: float("nan"))  # a pair member silent: not apart
    row = experiments.recovery_runs(["m3n2"], ["perfect"], 2, 300, 2.0, 3.0)[0][0]
    assert row[count] == 0 and np.isnan(row[key])


def test_a_csv_that_cannot_be_written_at_the_end_is_one_line_and_keeps_the_json(tmp_path, monkeypatch):
    import errno
    from contextlib import contextmanager

    import lookalike.bench.tables as tables

    @contextmanager
    def disk_full(path):
        raise OSError(errno.ENOSPC, "No space left on device")
        yield path

    monkeypatch.setattr(tables, "atomic_path", disk_full)
    out, csv = tmp_path / "s.json", tmp_path / "s.csv"
    r = CliRunner().invoke(app, ["bench", "shuffle", "--setups", "m3n2", "--trackers", "kalman_ha2", "--sequences",
                                 "1", "--frames", "20", "--json", str(out), "--csv", str(csv)])
    assert r.exit_code == 2 and "Traceback" not in r.output, r.output
    assert r.output.strip().splitlines()[-1] == f"error: --csv: cannot write {csv}: No space left on device"
    assert json.loads(out.read_text())["tables"]["shuffle"] and not csv.exists()
