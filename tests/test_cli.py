from pathlib import Path

import numpy as np
from typer.testing import CliRunner

from lookalike.cli import app
from lookalike.io import read_mot, write_mot
from lookalike.sim import BoxSceneConfig, simulate_boxes

runner = CliRunner()


def _det_file(tmp_path: Path) -> Path:
    scene = simulate_boxes(BoxSceneConfig(frames=30, seed=3))
    rows = []
    for f in scene.frames:
        for box, score in zip(f.detections.xywh, f.detections.score):
            rows.append([f.index + 1, -1, *box, score, -1, -1, -1])
    return write_mot(tmp_path / "seq" / "det" / "det.txt", np.array(rows))


def test_track_single_file(tmp_path):
    det = _det_file(tmp_path)
    out = tmp_path / "tracks.txt"
    result = runner.invoke(app, ["track", str(det), "-o", str(out), "--set", "min_hits=1"])
    assert result.exit_code == 0, result.output
    assert "frames/s" in result.output
    assert len(read_mot(out)) > 0


def test_track_folder_of_sequences(tmp_path):
    _det_file(tmp_path / "all")
    result = runner.invoke(app, ["track", str(tmp_path / "all"), "-o", str(tmp_path / "res")])
    assert result.exit_code == 0, result.output
    assert (tmp_path / "res" / "seq.txt").is_file()


def test_track_errors_are_readable(tmp_path):
    det = _det_file(tmp_path)
    r = runner.invoke(app, ["track", str(det), "-o", str(tmp_path / "o.txt"), "--tracker", "nope"])
    assert r.exit_code == 2 and "unknown tracker" in r.output
    r = runner.invoke(app, ["track", str(det), "-o", str(tmp_path / "o.txt"), "--set", "max_age=lots"])
    assert r.exit_code == 2 and "cannot read 'lots' as int" in r.output
    r = runner.invoke(app, ["track", str(det), "-o", str(tmp_path / "o.txt"), "--set", "colour=3"])
    assert r.exit_code == 2 and "no parameter 'colour'" in r.output
    bad = tmp_path / "bad" / "det.txt"
    bad.parent.mkdir()
    bad.write_text("1,-1,1,1,1,1,1\n2,-1,oops\n")
    r = runner.invoke(app, ["track", str(bad), "-o", str(tmp_path / "o.txt")])
    assert r.exit_code == 2 and "det.txt:2" in r.output


def test_trackers_listing():
    r = runner.invoke(app, ["trackers", "--names"])
    assert r.exit_code == 0 and "sort" in r.output.split()
    r = runner.invoke(app, ["trackers"])
    lines = r.output.splitlines()
    assert r.exit_code == 0 and all(len(line) <= 80 for line in lines), r.output
    assert sum(line.split()[0] in {"sort", "boxtrack", "set"} for line in lines if line.strip()) == 3
    assert any(line.startswith("sort") and "boxes" in line for line in lines)
    r = runner.invoke(app, ["trackers", "--details", "sort"], env={"COLUMNS": "200"})
    assert r.exit_code == 0 and "max_age" in r.output and "iou_threshold" in r.output
    r = runner.invoke(app, ["trackers", "--details", "no_such"])
    assert r.exit_code == 2 and "registered:" in r.output


def test_trackers_names_with_details_is_refused_not_half_ignored():
    r = runner.invoke(app, ["trackers", "--names", "--details", "sort"])
    assert r.exit_code == 2 and r.output.startswith("error: --names and --details sort: give one"), r.output


def test_demo_runs(tmp_path):
    r = runner.invoke(app, ["demo", "--quick", "-o", str(tmp_path / "demo")])
    assert r.exit_code == 0, r.output
    assert (tmp_path / "demo").is_dir()


def test_version_and_sorted_commands():
    from lookalike.io.results import lookalike_version

    r = runner.invoke(app, ["--version"])
    assert r.exit_code == 0 and r.output.strip() == f"lookalike {lookalike_version()}"
    for args in ([], ["bench"]):
        text = runner.invoke(app, [*args, "--help"], terminal_width=80).output
        names = [line.split()[0] for line in text.split("Commands:")[1].splitlines()
                 if line.startswith("  ") and not line.startswith("   ")]
        assert names == sorted(names) and len(names) >= 5, names


def _commands(group=None, path=()):
    from typer.main import get_command

    group = group or get_command(app)
    for name, cmd in getattr(group, "commands", {}).items():
        yield (*path, name)
        yield from _commands(cmd, (*path, name))


def test_help_wraps_within_80_columns_without_cut_sentences():
    for path in _commands():
        text = runner.invoke(app, [*path, "--help"], terminal_width=80).output
        long = [line for line in text.splitlines() if len(line) > 80]
        assert not long, (path, long)
        assert "…" not in text, path


def test_bench_options_mean_the_same_everywhere():
    from typer.main import get_command

    bench = get_command(app).commands["bench"]
    kinds = {}
    for cmd in bench.commands.values():
        for p in cmd.params:
            for opt in p.opts:
                if opt in ("--sequences", "--frames", "--setups", "--trackers", "--seed", "--json"):
                    kinds.setdefault(opt, set()).add((p.multiple, str(p.bare_type())))
    assert all(len(v) == 1 for v in kinds.values()), kinds


def test_piped_output_keeps_each_message_on_one_line(tmp_path):
    """Redirected to a file or a pipe, a long message is not wrapped at 80 columns (scripts read it by line)."""
    import os
    import subprocess
    import sys

    det = tmp_path / "det.txt"
    det.write_text("".join(f"{f},-1,{10 + f},20,30,40,0.9,-1,-1,-1\n" for f in range(1, 6)))
    out = tmp_path / ("a-result-file-with-a-name-long-enough-to-pass-eighty-columns-" + "x" * 40 + ".txt")
    env = {k: v for k, v in os.environ.items() if k != "COLUMNS"}
    done = subprocess.run([sys.executable, "-m", "lookalike", "track", "-t", "sort", str(det), "-o", str(out)],
                          capture_output=True, text=True, env=env, check=True)
    assert any(line.endswith(f"→ {out}") for line in done.stdout.splitlines()), done.stdout


def test_tracker_details_print_every_parameter_name_whole_at_80_columns():
    """The names ``--set`` takes are never cut with an ellipsis, however narrow the output."""
    import os
    import subprocess
    import sys

    from lookalike.trackers import tracker_parameters

    env = {**os.environ, "COLUMNS": "80"}
    for name in ("boxtrack", "diversort"):
        done = subprocess.run([sys.executable, "-m", "lookalike", "trackers", "--details", name], capture_output=True,
                              text=True, env=env, check=True)
        cells = {cell.strip() for line in done.stdout.splitlines() for cell in line.split("│")}
        assert {p.name for p in tracker_parameters(name)} <= cells, done.stdout
