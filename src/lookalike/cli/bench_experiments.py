"""``lookalike bench shuffle`` and ``bench recovery``: the robot-identification paper's control and recovery
experiments (:mod:`lookalike.bench.experiments`)."""

from __future__ import annotations

from pathlib import Path

import typer

from lookalike.bench.experiments import (
    DEFAULT_SEED,
    experiment_results,
    recovery_differences,
    recovery_runs,
    shuffle_rows,
)
from lookalike.bench.ident_paper import IDENT_VARIANTS
from lookalike.cli.app import check_names, check_outputs_or_fail, check_teams, command_line, fail, failing, split_list
from lookalike.cli.bench import (
    SETUPS_HELP,
    bench_app,
    print_differences,
    print_rows,
    trained_only,
    write_csv,
    write_results,
)
from lookalike.cli.progress import progress_bars
from lookalike.io.needs import identifier_names
from lookalike.sim import PRESET_NAMES
from lookalike.sim.presets import preset

SHUFFLE_TRACKERS, RECOVERY_TRACKERS = ("jpda", "lstm"), ("kalman_ha2", "jpda", "lstm")


@bench_app.command("shuffle")
def shuffle(
    setups: list[str] = typer.Option(list(PRESET_NAMES), "--setups", help=SETUPS_HELP),
    trackers: list[str] = typer.Option(list(SHUFFLE_TRACKERS), "--trackers",
                                       help="Identifiers (comma-separated or repeated)."),
    sequences: int = typer.Option(3, "--sequences", min=1, help="Test sequences per set-up."),
    frames: int = typer.Option(1000, "--frames", min=2, help="Frames per sequence."),
    seed: int = typer.Option(DEFAULT_SEED, "--seed", min=0, help="Base seed of the test sequences."),
    json_path: Path | None = typer.Option(None, "--json", help="Also write the rows as JSON (results schema)."),
    csv_path: Path | None = typer.Option(None, "--csv", help="Also write the rows as CSV."),
) -> None:
    """Control experiment: success rate on frames in order and in random order."""
    check_outputs_or_fail({"--json": json_path, "--csv": csv_path})
    setup_list, tracker_list = split_list(setups), split_list(trackers)
    _check_setups_and_trackers(setup_list, tracker_list)
    tracker_list = trained_only(tracker_list, SHUFFLE_TRACKERS, setup_list)
    with failing(ValueError), progress_bars() as progress:
        rows = shuffle_rows(setup_list, tracker_list, sequences, frames, seed, progress)
    print_rows("Control: frames in random order", rows)
    write_results(experiment_results("shuffle", rows, setup_list, sequences, frames, seed, command_line()),
                  json_path)
    write_csv(rows, csv_path)


@bench_app.command("recovery")
def recovery(
    setups: list[str] = typer.Option(list(PRESET_NAMES), "--setups", help=SETUPS_HELP),
    trackers: list[str] = typer.Option(list(RECOVERY_TRACKERS), "--trackers",
                                       help="Identifiers (comma-separated or repeated)."),
    sequences: int = typer.Option(3, "--sequences", min=1, help="Test sequences per set-up."),
    frames: int = typer.Option(900, "--frames", min=300, help="Frames per sequence."),
    swap_at_s: float = typer.Option(5.0, "--swap-at-s", help="When the swap starts, seconds."),
    swap_s: float = typer.Option(10.0, "--swap-s", help="How long reports stay swapped, seconds."),
    seed: int = typer.Option(DEFAULT_SEED, "--seed", min=0, help="Base seed of the test sequences."),
    json_path: Path | None = typer.Option(None, "--json", help="Also write the rows as JSON (results schema)."),
    csv_path: Path | None = typer.Option(None, "--csv", help="Also write the rows as CSV."),
) -> None:
    """Recovery experiment: swap two robots' reports, restore them, time the return to normal."""
    check_outputs_or_fail({"--json": json_path, "--csv": csv_path})
    setup_list, tracker_list = split_list(setups), split_list(trackers)
    _check_setups_and_trackers(setup_list, tracker_list)
    tracker_list = trained_only(tracker_list, RECOVERY_TRACKERS, setup_list)
    _check_swap(swap_at_s, swap_s, frames, setup_list)
    with failing(ValueError), progress_bars() as progress:
        rows, seconds = recovery_runs(setup_list, tracker_list, sequences, frames, swap_at_s, swap_s, seed, progress)
    print_rows(f"Recovery after {swap_s:g} s of swapped reports", rows)
    differences = recovery_differences(seconds, setup_list, tracker_list)
    print_differences(differences, tracker_list[0], "s", "Mean recovery time")
    options = {"swap_at_s": swap_at_s, "swap_s": swap_s}
    write_results(experiment_results("recovery", rows, setup_list, sequences, frames, seed, command_line(),
                                     options, differences), json_path)
    write_csv(rows, csv_path)


def _check_setups_and_trackers(setups: list[str], trackers: list[str]) -> None:
    """Fail in one line naming a team or identifier that does not exist."""
    check_teams("--setups", setups)
    check_names("--trackers", trackers, [*identifier_names(), *IDENT_VARIANTS], "identifier")


def _check_swap(swap_at_s: float, swap_s: float, frames: int, setups: list[str]) -> None:
    """Fail in one line unless the swap starts at >= 0 s, lasts > 0 s and ends before the sequences do."""
    rate = min(preset(s).frame_rate_hz for s in setups) if setups else 30.0
    length_s = frames / rate
    if not (swap_at_s >= 0 and swap_s > 0 and swap_at_s + swap_s < length_s):
        fail(f"--swap-at-s {swap_at_s:g} / --swap-s {swap_s:g}: the swap must start at >= 0 s, last > 0 s and end "
             f"before the sequences do ({frames} frames = {length_s:g} s at {rate:g} Hz)")
