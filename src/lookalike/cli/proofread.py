"""``lookalike proofread``: correct a tracking result's identities on its video, in the browser."""

from __future__ import annotations

import os
from pathlib import Path

import typer

from lookalike.cli.app import app, check_outputs_or_fail, console, fail, failing, note


@app.command()
def proofread(
    video: Path = typer.Option(..., "--video", help="The video the tracks were made on."),
    tracks: Path = typer.Option(..., "--tracks", help="The tracks to correct (MOTChallenge .txt)."),
    targets: int | None = typer.Option(
        None, "--targets", min=1,
        help="Known number of identities: each correction re-solves the offline closed set of N (as `track "
             "--targets N --offline`), so later frames that depended on it change too; tracks of `track --detector "
             "blob --targets N` re-solve from the video's cached blobs, with each animal's look. Without: plain "
             "edits."),
    detections: Path | None = typer.Option(
        None, "--detections", help="With --targets: the detections the tracks came from (the closed set is built "
                                   "from their online pass, as --offline does; default: from the tracks)."),
    frame_rate: float | None = typer.Option(None, "--frame-rate", min=0.001,
                                            help="Frames per second (default: the video's)."),
    output: Path | None = typer.Option(None, "-o", "--output",
                                       help="Corrected tracks, MOTChallenge (default: TRACKS_STEM.proofread.txt)."),
    log: Path | None = typer.Option(None, "--log",
                                    help="Corrections log, saved after every action and replayed when the page "
                                         "opens again (default: TRACKS_STEM.corrections.jsonl)."),
    port: int = typer.Option(8766, "--port", min=0, max=65535, help="Port (0: any free one)."),
    host: str = typer.Option("127.0.0.1", "--host",
                             help="Address to bind (others on the network can reach non-loopback ones)."),
    fresh: bool = typer.Option(False, "--fresh", help="Start over: move the saved log to LOG.bak."),
    export: bool = typer.Option(False, "--export",
                                help="Replay the saved log, write the corrected tracks and exit (no server)."),
) -> None:
    """Serve the proofreading page: the video with its tracks; click a box and say who it is from that frame on.

    Corrections: assign an identity, swap two ids, merge, split, delete, undo. With --targets N each correction
    re-solves the closed set and the latest correction wins over earlier ones that contradict it. The log is saved
    after every action; export (the button or --export) writes the corrected tracks."""
    from lookalike.io.rules import not_a_file
    from lookalike.io.video_frames import video_info
    from lookalike.proofread import Correction, Session
    from lookalike.viz.label.proofread import ProofreadApp, make_proofread_server

    for option, path in (("--video", video), ("--tracks", tracks), ("--detections", detections)):
        if path is not None and not path.is_file():
            fail(f"{option}: {not_a_file(path)}" + (" (the page reads a video file, not a folder of images)"
                                                     if option == "--video" and path.is_dir() else ""))
    if detections is not None and targets is None:
        fail("--detections needs --targets N (plain edits use the tracks alone)")
    log = log or tracks.with_name(f"{tracks.stem}.corrections.jsonl")
    output = output or tracks.with_name(f"{tracks.stem}.proofread.txt")
    check_outputs_or_fail({"--output": output, "--log": log}, [video, tracks, detections])
    if targets is None and not fresh and log.is_file():
        from lookalike.proofread.session import log_header

        with failing(ValueError, OSError, prefix=f"{log}: "):
            logged = (log_header(log) or {}).get("n_targets")
        if logged is not None:
            targets = int(logged)
            console.print(f"{log.name} was made with --targets {targets}: corrections re-solve with it (--fresh to "
                          "start over)", markup=False)
    with failing(ValueError, prefix="--video: "):
        fps = video_info(video)[1]
    solver = None
    if targets is not None and detections is None:  # (tracks of `track --detector blob --targets N`: with the look)
        from lookalike.pipeline.proofread_input import blob_solver_input

        with failing(ValueError, OSError):
            solver = blob_solver_input(video, tracks, targets, frame_rate or fps)
        if solver is not None:
            console.print("corrections re-solve from the video's cached blobs, with each animal's look", markup=False)
    det_table = None
    if detections is not None:  # read as `track` read them (another layout: a note says what was assumed)
        from lookalike.io.det_format import read_detections

        with failing(ValueError):
            det_table, notes = read_detections(detections)
        for line in notes:
            note(f"{detections}: {line}")
        if det_table is not None and not len(det_table):
            fail(f"--detections: {detections}: no detections to solve the closed set from")
    with failing(ValueError):
        session = Session(tracks, frame_rate=frame_rate or fps, n_targets=targets, detections=det_table,
                          solver_input=solver[0] if solver else None, shapes=solver[1] if solver else None,
                          parts=solver[2] if solver else None)
    if fresh and log.exists():
        os.replace(log, log.with_name(log.name + ".bak"))
    elif log.exists():
        with failing(ValueError):
            session.replay(log)
        console.print(f"replayed {len(session.corrections)} corrections from {log.name}", markup=False)
    page = ProofreadApp(session, video, log, output, Correction.from_json)
    if export:
        r = page.export()
        console.print(f"wrote {r['tracks']} ({r['rows']} rows) and {r['log']}", markup=False)
        return
    with failing(OSError, prefix=f"cannot listen on {host}:{port}: "):
        server = make_proofread_server(page, host, port)
    from lookalike.cli.label import serve_until_stopped

    serve_until_stopped(server, host, f"proofreading {tracks.name} on {video.name}", f"corrections saved to {log.name}",
                        "corrections")
