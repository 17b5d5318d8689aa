"""``lookalike demo``: robots identified from their heading reports and look-alike divers re-identified after long
absences, simulated, rendered and tracked by every relevant tracker, with videos, plots and a ``report.html``.
:data:`QUICK` is a reduced version (seconds)."""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from pathlib import Path
from typing import Any

from lookalike.bench.ident import ident_results, ident_table
from lookalike.io.results import Results
from lookalike.sim import PRESET_NAMES, preset, preset_label
from lookalike.sim.divers import SCENARIOS, VALIDATION_SCENARIOS, scenario
from lookalike.sim.divers_run import fit_diver_features
from lookalike.viz.divers_scene import LEGEND as DIVER_LEGEND
from lookalike.viz.divers_scene import run_diver_scenario
from lookalike.viz.plots import grouped_bar_chart
from lookalike.viz.report import EMBED_MAX_BYTES, HtmlReport
from lookalike.viz.robots_scene import HOLD_FRAMES, run_robot_scene
from lookalike.viz.robots_scene import LEGEND as ROBOT_LEGEND

ROBOT_TRACKERS = ("kalman_ha", "kalman_ha2", "jpda")
DIVER_TRACKERS = ["sort", "deepsort", "diversort"]
IDENT_COLS = ["Setup", "Tracker", "Success rate (%)", "Localisation error (m)", "Frames/s"]
DIVER_COLS = ["Scenario", "Tracker", "IDF1", "HOTA", "MOTA", "IDSW", "Frames/s"]
# step(description, total) -> advance(): one progress bar per phase
Step = Callable[[str, int], Callable[[], None]]


@dataclasses.dataclass(frozen=True)
class DemoSize:
    """How much the demo simulates (frames per scene and table). The defaults keep ``lookalike demo``
    near 50 s of CPU time (one core): measured in docs/getting-started.md."""

    robot_frames: int = 240
    ident_sequences: int = 2
    ident_frames: int = 400
    diver_video_frames: int = 240
    diver_frames: int = 100
    diver_scenarios: int = len(SCENARIOS)
    fit_frames: int = 150


QUICK = DemoSize(robot_frames=45, ident_sequences=1, ident_frames=120, diver_video_frames=40, diver_frames=30,
                 diver_scenarios=2, fit_frames=30)


@dataclasses.dataclass
class DemoResult:
    """What the demo wrote (name → path) and its tables."""

    files: dict[str, Path]
    robot_rows: list[dict[str, Any]]
    ident_rows: list[dict[str, Any]]
    diver_rows: list[dict[str, Any]]
    notes: dict[str, str | None]
    starts: dict[str, float] = dataclasses.field(default_factory=dict)  # where each video starts (s): its warm-up


def lstm_status(setup: str) -> str | None:
    """None when shipped LSTM weights exist for preset ``setup``, else why the LSTM is left out."""
    from lookalike.trackers.lstm.weights import shipped_weights_path
    from lookalike.trackers.parts.weights_io import CheckpointError

    cfg = preset(setup)
    try:
        shipped_weights_path(cfg.n_agents, cfg.max_detections)
    except CheckpointError:
        return f"no shipped LSTM weights for {preset_label(setup)} (train them with `make train`)"
    return None


def _silent(description: str, total: int) -> Callable[[], None]:
    return lambda: None


def _divers(output: Path, size: DemoSize, step: Step,
            rerun: Any) -> tuple[list[dict[str, Any]], dict[str, Path], float | None]:
    adv = step("Divers: appearance features (validation)", 1)
    val = tuple(dataclasses.replace(sc, frames=min(sc.frames, size.fit_frames)) for sc in VALIDATION_SCENARIOS)
    extractor = fit_diver_features(val)
    adv()
    video_sc = dataclasses.replace(scenario("ocean_four_long_absences"), frames=size.diver_video_frames)
    rows, files, start_s = run_diver_scenario(
        video_sc, extractor, DIVER_TRACKERS, out_dir=output, video_tracker="diversort",
        advance=step(f"Divers {video_sc.name}: render + track", video_sc.frames), rerun=rerun)
    others = [sc for sc in SCENARIOS if sc.name != video_sc.name][: max(size.diver_scenarios - 1, 0)]
    adv = step("Divers: other scenarios", len(others) * size.diver_frames)
    for sc in others:
        more, _, _ = run_diver_scenario(dataclasses.replace(sc, frames=size.diver_frames), extractor, DIVER_TRACKERS,
                                     advance=adv)
        rows += more
    return rows, {f"divers-{k}": v for k, v in files.items()}, start_s


def diver_results(rows: list[dict[str, Any]], size: DemoSize, command: str = "") -> Results:
    """The demo's diver rows (metrics in %) as a results document: table ``divers``, dataset
    ``divers-sim``, one row per scenario (``sequence``) and tracker, fractions."""
    scenarios = list(dict.fromkeys(r["Scenario"] for r in rows))
    frames = size.diver_video_frames + size.diver_frames * max(len(scenarios) - 1, 0)
    doc = Results("demo divers", command=command, sequences=len(scenarios), frames=frames,
                  options={"diver_video_frames": size.diver_video_frames, "diver_frames": size.diver_frames})
    for r in rows:
        metrics = {k.lower(): r[k] / 100 for k in ("IDF1", "HOTA", "MOTA") if k in r}
        metrics.update({"idsw": r.get("IDSW"), "frames_per_s": r.get("Frames/s")})
        doc.add("divers", dataset="divers-sim", sequence=r["Scenario"], tracker=r["Tracker"], metrics=metrics)
    return doc


def run_demo(output: Path, seed: int, size: DemoSize, robot_preset: str, rerun: Any = None,
             step: Step = _silent, command: str = "") -> DemoResult:
    """Run the whole demo into ``output``. ``rerun``: an optional :class:`~lookalike.viz.rerun_log.RerunLogger` for
    the video scenes; ``command``: the command line recorded in the JSON files' header."""
    if seed < 0:
        raise ValueError(f"seed: a whole number >= 0, got {seed}")
    output.mkdir(parents=True, exist_ok=True)
    notes = {s: lstm_status(s) for s in PRESET_NAMES}
    video_tracker = "lstm" if notes[robot_preset] is None else "kalman_ha2"
    robot_trackers = list(ROBOT_TRACKERS) + (["lstm"] if notes[robot_preset] is None else [])
    adv = step(f"Robots {preset_label(robot_preset)}: render + identify", size.robot_frames)
    robots = run_robot_scene(output, preset_name=robot_preset, frames=size.robot_frames, seed=seed,
                             trackers=robot_trackers, video_tracker=video_tracker, advance=adv, rerun=rerun)
    files = {f"robots-{k}": v for k, v in robots.files.items()}
    ident_rows: list[dict[str, Any]] = []
    adv = step("Robot identification, all set-ups", len(PRESET_NAMES))
    for s in PRESET_NAMES:
        names = list(ROBOT_TRACKERS) + (["lstm"] if notes[s] is None else [])
        ident_rows += ident_table([s], names, size.ident_sequences, size.ident_frames, seed=900_000 + seed)
        adv()
    diver_rows, diver_files, diver_start = _divers(output, size, step, rerun)
    files.update(diver_files)
    files["idf1"] = grouped_bar_chart(output / "divers-idf1.png", diver_rows, "Scenario", "Tracker", "IDF1",
                                      ylabel="IDF1 (%)", title="Diver tracking: IDF1 per scenario")
    files["ident-chart"] = grouped_bar_chart(output / "robots-ident.png", ident_rows, "Setup", "Tracker",
                                             "Success rate (%)", title="Robot identification success rate")
    ident_results(ident_rows, list(PRESET_NAMES), size.ident_sequences, size.ident_frames, 900_000 + seed,
                  command).write(output / "robots-ident.json")
    diver_results(diver_rows, size, command).write(output / "divers.json")
    starts = {"robots": robots.start_s, "divers": diver_start or 0.0}
    result = DemoResult(files, robots.rows, ident_rows, diver_rows, notes, starts)
    files["report"] = write_report(output, result, video_tracker, size)
    return result


def write_report(output: Path, result: DemoResult, video_tracker: str, size: DemoSize) -> Path:
    """The demo's ``report.html``: tables, pictures, and the videos (embedded when small, else linked) with their
    first frame as poster and their legend above them."""
    files, starts = result.files, result.starts
    report = HtmlReport("lookalike demo: identical robots and look-alike divers")
    small = all(files[v].stat().st_size <= EMBED_MAX_BYTES for v in ("robots-video", "divers-video"))
    report.text("Everything here was simulated and rendered by lookalike itself; no data was downloaded. "
                "Re-run with `lookalike demo`. " + ("This page holds every picture and video; " if small else
                "This page holds every picture; its videos are the MP4 files beside it (keep them together); ")
                + f"the files it was made from are in its folder ({output.name}/).", note=True)
    report.heading("Identical robots identified from their heading reports")
    report.text(f"Each detection is labelled with the robot it belongs to (colours) or as a false positive, by "
                f"the {video_tracker} identifier, from the robots' own heading reports. Red frames mark wrong labels. "
                f"The video starts where the identifier's warm-up ends, at {starts.get('robots', 0.0):.1f} s: the "
                f"first frame with a robot in view from which every label is right for {HOLD_FRAMES} frames (if "
                f"that comes by half-way, else the first frame by then with every label right); its percentage "
                f"counts the labels from there. The table scores every frame.")
    report.video(files["robots-video"], "Annotated robot video (MP4, H.264)", relative_to=output, width=640,
                 poster=files["robots-still"], legend=ROBOT_LEGEND)
    report.image(files["robots-birdseye"], "True vs estimated robot paths, seen from above", width=560)
    report.table(result.robot_rows, IDENT_COLS, caption="The video scene, every frame")
    report.heading("Robot identification, the paper's three set-ups")
    for why in (w for w in result.notes.values() if w):
        report.text(f"LSTM left out: {why}.", note=True)
    report.table(result.ident_rows, IDENT_COLS,
                 caption=f"{size.ident_sequences} × {size.ident_frames} simulated frames per set-up")
    report.image(files["ident-chart"], "Identification success rate (%)", width=560)
    report.heading("Look-alike divers re-identified after long absences")
    report.text(f"Diver SORT's tracks on the rendered video. The video starts where the trackers' warm-up ends, at "
                f"{starts.get('divers', 0.0):.1f} s: the first frame where every diver in view has a track and no "
                f"track is false (or, if none comes by half-way, the one with the fewest misses); its percentage "
                f"counts the divers in view that have a track from there. The table scores every frame.")
    report.video(files["divers-video"], "Annotated diver video (MP4, H.264)", relative_to=output, width=640,
                 poster=files["divers-still"], legend=DIVER_LEGEND)
    report.image(files["idf1"], "IDF1 per scenario and tracker", width=640)
    report.table(result.diver_rows, DIVER_COLS, caption="Diver tracking (IDF1, HOTA, MOTA in %; scenarios shortened)")
    report.heading("Try next")
    report.code("lookalike trackers\n"
                "lookalike bench ident\n"
                "lookalike bench divers --png idf1.png\n"
                f"lookalike render --video {output}/divers-raw.mp4 --tracks {output}/divers-sort.txt "
                f"-o {output}/divers-sort.mp4")
    return report.write(output / "report.html")


__all__ = ["DIVER_COLS", "IDENT_COLS", "QUICK", "DemoResult", "DemoSize", "diver_results", "lstm_status", "run_demo",
           "write_report"]
