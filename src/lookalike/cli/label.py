"""``lookalike label``: label a robot sequence's detections with identities in the browser."""

from __future__ import annotations

import getpass
import ipaddress
import re
from http.server import HTTPServer
from pathlib import Path

import typer
from rich.markup import escape

from lookalike.bench.ident import identify
from lookalike.cli.app import app, check_outputs_or_fail, console, fail, failing
from lookalike.sim import RobotSequence
from lookalike.trackers import tracker_names


def login_name() -> str:
    """The user's login name as a labeller id (characters other than letters, digits, ``.``, ``_``,
    ``-`` become ``_``), or ``anonymous``."""
    try:
        name = getpass.getuser()
    except (OSError, KeyError, ImportError):
        return "anonymous"
    name = re.sub(r"[^A-Za-z0-9._-]", "_", name)[:64].lstrip("._-")
    return name or "anonymous"


def tracker_labels(name: str, sequence: RobotSequence) -> list[list[int]]:
    """Per-frame detection labels from running registered tracker ``name`` over ``sequence``."""
    return [labels.tolist() for labels in identify(name, sequence)]


@app.command()
def label(
    sequence: Path = typer.Argument(..., help="A robot sequence (.jsonl from `lookalike simulate`)."),
    tracks: str | None = typer.Option(
        None, "--tracks",
        help="Starting labels: a tracker name (run on the sequence), a label file (.json), a labelled "
             "sequence (.jsonl) or a MOTChallenge file (.txt) from the export. Ignored when saved labels exist."),
    port: int = typer.Option(8765, "--port", min=0, max=65535, help="Port (0: any free one)."),
    host: str = typer.Option("127.0.0.1", "--host",
                             help="Address to bind (others on the network can reach non-loopback ones)."),
    benchmark: bool = typer.Option(False, "--benchmark",
                                   help="Human benchmark: hide the truth, time the session, score it at the end "
                                        "and write STEM.human-LABELLER.json (time, success rate, labeller id)."),
    labeller: str | None = typer.Option(None, "--labeller",
                                        help="Who labels (the benchmark result's id; default: your login name)."),
    results: Path | None = typer.Option(None, "--results",
                                        help="Folder for the benchmark result file (default: the sequence's)."),
    fresh: bool = typer.Option(False, "--fresh", help="Start over: move saved labels to <stem>.labels.json.bak."),
    export: bool = typer.Option(False, "--export",
                                help="Write the exports from the saved labels and exit (no server)."),
) -> None:
    """Serve the labelling page: click detections to cycle their robot (left forward, right back).

    Labels are saved after every click to STEM.labels.json beside the sequence. Export (the button or --export) writes
    STEM.labelled.jsonl (simulator truth format) and STEM.labels.mot.txt (MOTChallenge, positions in the world columns);
    with --benchmark, --export also (re)writes the finished session's result file. `bench ident --lengths ... --human
    DIR` puts the result files beside the identifiers (the robot-identification paper's Table III)."""
    from lookalike.io.robot_sequences import read_robot_sequence
    from lookalike.viz.label import load_labels, make_server, open_label_app

    if not sequence.is_file():
        fail(f"SEQUENCE: {sequence}: no such file")
    if benchmark and tracks:
        fail("--benchmark starts from no labels; leave out --tracks")
    # the benchmark result's folder, checked before the session (or --export) writes anything
    check_outputs_or_fail({"--results": results if benchmark else None}, [sequence], folders={"--results"})
    initial, source = None, "empty"
    if tracks and not Path(tracks).is_file() and tracks not in tracker_names():
        fail(f"--tracks: {tracks!r} is neither a file nor a tracker ({', '.join(tracker_names())})")
    with failing(ValueError):
        if tracks and not fresh and (sequence.with_name(f"{sequence.stem}.labels.json")).exists():
            console.print("saved labels exist: --tracks ignored (use --fresh to start over from them)")
        elif tracks:
            seq = read_robot_sequence(sequence)
            if Path(tracks).is_file():
                initial, source = load_labels(tracks, seq), f"file {Path(tracks).name}"
            else:
                console.print(f"running {tracks} on {sequence.name} …", markup=False)
                initial, source = tracker_labels(tracks, seq), f"tracker {tracks}"
        label_app = open_label_app(sequence, initial, source, benchmark, fresh,
                                   labeller if labeller is not None else login_name(), results)
    if export:
        r = label_app.export()
        console.print(f"wrote {r['truth']} and {r['mot']} ({r['mot_rows']} rows, {r['unset']} not labelled) "
                      f"in {label_app.folder}", markup=False)
        if benchmark:
            with failing(ValueError, OSError, prefix="--benchmark: "):
                console.print(f"wrote {label_app.write_result()}", markup=False)
        return
    with failing(OSError, prefix=f"cannot listen on {host}:{port}: "):
        server = make_server(label_app, host, port)
    serve_until_stopped(server, host, f"labelling {sequence.name} ({len(label_app.sequence)} frames)",
                        f"labels saved to {label_app.store.path.name}", "labels")


def serve_until_stopped(server: HTTPServer, host: str, what: str, saved: str, kept: str) -> None:
    """Print ``what`` with the page's address and ``saved``, serve until Ctrl-C, then say ``kept`` are saved."""
    try:
        if not ipaddress.ip_address(str(server.server_address[0])).is_loopback:
            console.print(f"[yellow]warning:[/] {escape(host)} is reachable from other machines")
    except ValueError:
        pass
    url = f"http://{host if ':' not in host else f'[{host}]'}:{server.server_address[1]}/"
    console.print(f"{escape(what)} at [bold]{url}[/] — {escape(saved)}; Ctrl-C to stop", highlight=False)
    try:
        server.serve_forever()
    except KeyboardInterrupt:
        pass
    finally:
        server.server_close()
    console.print(f"stopped; {kept} are saved", highlight=False)
