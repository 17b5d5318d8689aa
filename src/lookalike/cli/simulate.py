"""``lookalike simulate``: write simulated robot-world sequences (JSON Lines, one file each), or with ``--arena``
rendered arenas of look-alike animals (a video and its truth)."""

from __future__ import annotations

from pathlib import Path

import typer

from lookalike.cli.app import app, check_names, check_outputs_or_fail, check_teams, console, fail, failing, require
from lookalike.io.robot_sequences import write_robot_sequence
from lookalike.io.rosbag import write_bag
from lookalike.sim import DEFAULT_NOISE, NOISE_MODELS, preset, simulate_robots
from lookalike.sim.presets import TEAM_HELP
from lookalike.sim.robot_camera import pixel_camera
from lookalike.viz.robot_pixels import render_robot_frames


@app.command()
def simulate(
    preset_name: str = typer.Option("m5n3", "--preset", help=f"The team: {TEAM_HELP}."),
    frames: int | None = typer.Option(None, "--frames", min=1, show_default=False,
                                      help="Frames per sequence (robots: 1000 at 30 Hz; --arena: 500 at 28 Hz)."),
    sequences: int = typer.Option(1, "--sequences", min=1, help="Number of sequences (seeds seed, seed+1, ...)."),
    seed: int = typer.Option(0, "--seed", min=0, help="Seed of the first sequence."),
    output: Path = typer.Option(..., "-o", "--output", help="Folder for the .jsonl files."),
    noise: str = typer.Option(DEFAULT_NOISE, "--noise",
                              help="Position-noise model: paper (the robot-identification paper's, larger across the "
                              "image) or ours (larger in depth)."),
    bag: bool = typer.Option(False, "--bag", help="Also write each sequence as a rosbag2 folder (ROS 2 messages: "
                             "headings, detections, truth; the 'ros' extra)."),
    images: bool = typer.Option(False, "--images", help="With --bag: render the camera frames into the bag "
                                "(sensor_msgs/Image; the 'vision' extra)."),
    arena: int | None = typer.Option(None, "--arena", min=1, show_default=False,
                                     help="Instead of robots: render an arena of this many look-alike animals "
                                     "(fish-like, touching and crossing) into -o: arena.avi, gt.txt, points.csv (a "
                                     "folder per seed with --sequences)."),
) -> None:
    """Simulate identical robots seen by an observer, with heading reports; write JSON Lines files.

    Format: see ``lookalike.io.robot_sequences`` (a header line, then one object per frame with detections, received
    reports and the truth)."""
    require(*(["cv2"] if arena is not None or (bag and images) else []), *(["rosbags"] if bag else []))
    check_outputs_or_fail({"-o/--output": output}, folders={"-o/--output"})
    if arena is not None:
        if bag:
            fail("--bag: goes with the robots, not --arena")
        return _arenas(arena, frames, sequences, seed, output)
    frames = frames or 1000
    check_teams("--preset", [preset_name])
    check_names("--noise", [noise], NOISE_MODELS, "noise model")
    if images and not bag:
        fail("--images: goes with --bag (the images are written into the bag)")
    cfg = preset(preset_name, noise)
    for k in range(sequences):
        seq = simulate_robots(cfg, frames, seed + k)
        path = write_robot_sequence(output / f"{preset_name}-{seed + k:06d}.jsonl", seq)
        a = seq.arrays
        console.print(f"wrote {path}: {frames} frames, {int(a.det_valid.sum())} detections, "
                      f"{len(a.reports.agent_id)} reports", markup=False)
        if bag:
            frames_bgr = (r.image for r in render_robot_frames(seq, pixel_camera(), seed + k)) if images else None
            with failing(ValueError, OSError, prefix="--bag: "):
                console.print(f"wrote {write_bag(path.with_suffix(''), seq, frames_bgr)} (rosbag2)", markup=False)
        for line in seq.view_summary():
            console.print(line, markup=False, style="yellow" if line.startswith("warning") else None)


def _arenas(animals: int, frames: int | None, sequences: int, seed: int, output: Path) -> None:
    """``--arena``: write each seed's arena into ``output`` (or ``output/arena-SEED`` for several)."""
    import dataclasses

    from lookalike.io.arena_files import write_arena
    from lookalike.sim.arena import ArenaConfig

    cfg = dataclasses.replace(ArenaConfig(), n_animals=animals, frames=frames or ArenaConfig().frames)
    for s in range(seed, seed + sequences):
        with failing(ValueError, OSError, prefix="--arena: "):
            files = write_arena(output if sequences == 1 else output / f"arena-{s:06d}", cfg, s)
        console.print(f"wrote {files.video}, {files.gt.name}, {files.points.name}: {animals} animals, {cfg.frames} "
                      f"frames, {files.arena.contacts} contacts (two animals' centres within a body length)",
                      markup=False)
