"""``lookalike bench``: benchmarks that print tables, and the table printing they share."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import Any

import typer
from rich.table import Table

from lookalike.bench.ident import (
    DEFAULT_SEED,
    IDENT_COLUMNS,
    IDENT_TRACKERS,
    ident_differences,
    ident_results,
    ident_runs,
    weights_missing,
)
from lookalike.bench.ident_paper import IDENT_VARIANTS, margin_rows
from lookalike.bench.paired import Comparison, comparison_rows, difference_title
from lookalike.bench.tables import write_rows
from lookalike.cli.app import (
    SortedGroup,
    app,
    check_names,
    check_outputs_or_fail,
    check_teams,
    command_line,
    fail,
    failing,
    print_whole,
    split_list,
    warn,
)
from lookalike.cli.progress import progress_bars
from lookalike.io.needs import identifier_names
from lookalike.io.results import Results
from lookalike.sim import PRESET_NAMES, preset_label
from lookalike.sim.presets import TEAM_HELP, team_size

bench_app = typer.Typer(help="Benchmarks that print tables (also written with --json/--csv).", no_args_is_help=True,
                        cls=SortedGroup, rich_markup_mode=None)
app.add_typer(bench_app, name="bench")
SETUPS_HELP = f"Teams (comma-separated or repeated): {TEAM_HELP}."
TEXT_COLUMNS = ("Setup", "Tracker", "Identifier", "Scenario", "Labeller", "Sequence")


def rich_table(title: str | None, rows: list[dict[str, Any]], columns: Sequence[str] | None = None) -> Table:
    """Table rows (dicts) as a rich table: text columns left and never cut, numbers right with thousands separators."""
    columns = list(columns if columns is not None else (rows[0] if rows else []))
    table = Table(title=title)
    cells = [[f"{r[c]:,}" if isinstance(r[c], (int, float)) else str(r[c]) for c in columns] for r in rows]
    for k, c in enumerate(columns):  # no cell is ever cut ("kalman…"): headers wrap at spaces instead
        widest = max([len(row[k]) for row in cells] + [max((len(w) for w in c.split()), default=0)])
        table.add_column(c, justify="left" if c in TEXT_COLUMNS else "right", min_width=widest)
    for row in cells:
        table.add_row(*row)
    return table


def print_rows(title: str | None, rows: list[dict[str, Any]], columns: Sequence[str] | None = None) -> None:
    """Print table rows (dicts) with rich (:func:`rich_table`); wider than the terminal rather than cut."""
    print_whole(rich_table(title, rows, columns))  # (minimum: every cell whole, headers wrapped at spaces)


def print_differences(differences: Sequence[Comparison], baseline: str, unit: str, figure: str = "") -> None:
    """Print the difference table of :mod:`lookalike.bench.paired` comparisons (nothing when there are none)."""
    if differences:
        print_rows(difference_title(baseline, unit, figure), comparison_rows(differences, unit))


def trained_only(trackers: list[str], default: Sequence[str], setups: list[str]) -> list[str]:
    """``trackers``, less the LSTMs without shipped weights for one of ``setups`` when ``trackers`` is the default
    list (a warning names them); an LSTM asked for by name stays (and fails in one line)."""
    if trackers != list(default):
        return trackers
    teams = [team_size(s) for s in setups]
    left = [t for t in trackers if any(weights_missing(t, n, m) for m, n, _ in teams)]
    if left:
        warn(f"{', '.join(left)} left out: no shipped weights for a team of --setups (use set, or name it in "
             "--trackers to see the error)")
    return [t for t in trackers if t not in left]


def write_results(doc: Results, path: Path | None) -> None:
    """Write a results document to ``path`` (if given); a one-line error when it cannot be written."""
    if path is None:
        return
    try:
        doc.write(path)
    except OSError as exc:
        fail(f"--json: cannot write {path}: {exc.strerror or exc}")


def write_csv(rows: list[dict[str, Any]], path: Path | None, columns: Sequence[str] | None = None) -> None:
    """Write table rows as CSV to ``path`` (if given); a one-line error when it cannot be written (the tables are
    printed and any --json written by then)."""
    if path is None:
        return
    try:
        write_rows(rows, None, path, columns)
    except OSError as exc:
        fail(f"--csv: cannot write {path}: {exc.strerror or exc}")


@bench_app.command("ident")
def ident(
    setups: list[str] = typer.Option(list(PRESET_NAMES), "--setups", help=SETUPS_HELP),
    trackers: list[str] = typer.Option(list(IDENT_TRACKERS), "--trackers",
                                       help="Identifiers (comma-separated or repeated)."),
    sequences: int = typer.Option(10, "--sequences", min=1, help="Test sequences per set-up."),
    frames: int = typer.Option(1000, "--frames", min=1, help="Frames per sequence."),
    seed: int = typer.Option(DEFAULT_SEED, "--seed", min=0, help="Base seed of the test sequences."),
    json_path: Path | None = typer.Option(None, "--json", help="Also write the rows as JSON."),
    csv_path: Path | None = typer.Option(None, "--csv", help="Also write the rows as CSV."),
    noise: str = typer.Option("ours", "--noise",
                              help="Simulator position noise: paper (the robot-identification paper's) or ours."),
    lengths: str | None = typer.Option(
        None, "--lengths", help="The paper's Table III instead: success rate on random windows of these lengths "
        "(frames, comma-separated, e.g. 200,400,800) and on the whole recordings."),
    draws: int = typer.Option(4, "--draws", min=1, help="Random windows per length (Table III)."),
    recordings: Path | None = typer.Option(
        None, "--recordings", help="Table III on the robot-sequence .jsonl files of this folder (one set-up) "
        "instead of the simulated test sequences."),
    human: Path | None = typer.Option(
        None, "--human", help="Table III: add a 'human' row from the result files (*.human-*.json) that "
        "`lookalike label --benchmark` wrote in this folder (default: the --recordings folder)."),
    weights: Path | None = typer.Option(
        None, "--weights", help="Exported weights (.npz) for the lstm and lstm-lowpass rows instead of the "
        "shipped ones, e.g. a training run's model.npz (one set-up)."),
) -> None:
    """The robot-identification paper's Table I: identification success rate per set-up and identifier (+ error, speed).
    With --lengths or --recordings: the paper's Table III protocol."""
    check_outputs_or_fail({"--json": json_path, "--csv": csv_path}, [weights], input_folders=[recordings, human])
    setup_list, tracker_list = split_list(setups), split_list(trackers)
    check_teams("--setups", setup_list)
    check_names("--trackers", tracker_list, [*identifier_names(), *IDENT_VARIANTS], "identifier")
    check_names("--noise", [noise], ("paper", "ours"), "noise model")
    if weights is not None and (lengths is not None or recordings is not None or human is not None):
        fail("--weights: for Table I only (not with --lengths, --recordings or --human)")
    if lengths is not None or recordings is not None or human is not None:
        table3_command(setup_list, tracker_list, sequences, frames, seed, noise, lengths, draws, recordings,
                       json_path, csv_path, human)
        return
    with failing(ValueError, FileNotFoundError), progress_bars() as progress:
        rows, counts = ident_runs(setup_list, tracker_list, sequences, frames, seed, noise, progress,
                                  str(weights) if weights else None)
    labels = [preset_label(s) for s in setup_list]
    rate = {(r["Setup"], r["Tracker"]): f"{v:.1f}%" if isinstance(v := r["Success rate (%)"], float) else str(v)
            for r in rows}
    summary = [{"Tracker": name, **{label: rate[(label, name)] for label in labels}} for name in tracker_list]
    print_rows(f"Robot identification success rate, {sequences} × {frames} frames per set-up", summary)
    print_rows("Per set-up details", rows, IDENT_COLUMNS)
    margins = margin_rows(rows, setup_list, labels)
    if margins:
        print_rows("LSTM margins over Kalman-HA on the same sequences, beside the paper's (Table I)", margins)
    differences = ident_differences(counts, setup_list, tracker_list)
    print_differences(differences, tracker_list[0], "points")
    write_results(ident_results(rows, setup_list, sequences, frames, seed, command_line(), noise,
                                str(weights) if weights else None, differences), json_path)
    write_csv(rows, csv_path)


def table3_command(setups: list[str], trackers: list[str], sequences: int, frames: int, seed: int, noise: str,
                   lengths: str | None, draws: int, recordings: Path | None, json_path: Path | None,
                   csv_path: Path | None, human: Path | None = None) -> None:
    """``bench ident --lengths/--recordings/--human``: the paper's Table III per set-up (or on the recordings),
    with the human benchmark's sessions when there are result files."""
    from lookalike.bench.table3 import DEFAULT_LENGTHS, table3_results, table3_table

    try:
        length_list = [int(v) for v in split_list([lengths])] if lengths else list(DEFAULT_LENGTHS)
    except ValueError:
        fail(f"--lengths: expected comma-separated frame counts, got {lengths!r}")
    if not length_list:
        fail(f"--lengths: no frame count given (e.g. {','.join(map(str, DEFAULT_LENGTHS))})")
    sessions: list[dict[str, Any]] = []
    with failing(ValueError, FileNotFoundError), progress_bars() as progress:
        rows = table3_table(setups, trackers, sequences, frames, seed, noise, length_list, draws, recordings,
                            progress, human, sessions)
    print_rows(f"Success rate by sequence length (the paper's Table III protocol: {draws} random windows per "
               "length, then whole recordings)", rows)
    if sessions:
        print_rows("Human benchmark sessions (lookalike label --benchmark): the 'human' rows", sessions)
    write_results(table3_results(rows, setups, sequences, frames, seed, noise, length_list, draws, recordings,
                                 command_line()), json_path)
    write_csv(rows, csv_path)


__all__ = ["bench_app", "print_rows", "rich_table", "write_csv", "write_results"]
