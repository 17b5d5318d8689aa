"""First runs: what ``lookalike --help`` imports, the compact tracker listing, the message when numba compiles."""

from __future__ import annotations

import os
import subprocess
import sys

import pytest


def _imported(code: str, modules: tuple[str, ...]) -> list[str]:
    probe = f"{code}\nimport sys\nprint('imported:', *[m for m in {modules!r} if m in sys.modules])"
    out = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, check=True)
    return out.stdout.splitlines()[-1].split()[1:]


HEAVY = ("scipy.stats", "scipy.optimize", "numba", "cv2", "torch", "matplotlib", "onnxruntime")


def test_building_the_whole_command_line_imports_no_heavy_package():
    # imported as a library every command module is imported, as for `lookalike --help`
    assert _imported("import lookalike.cli", HEAVY) == []


def test_the_help_of_the_script_imports_no_heavy_package():
    code = ("import sys; sys.argv = ['lookalike', '--help']\nfrom lookalike.cli import main\n"
            "try:\n    main()\nexcept SystemExit:\n    pass")
    assert _imported(code, HEAVY) == []


def test_compact_listing_fits_80_columns_with_every_tracker():
    from lookalike.cli.trackers import compact_lines
    from lookalike.trackers.registry import tracker_names

    lines = compact_lines(tracker_names())
    assert len(lines) == len(tracker_names()) + 1 and all(len(line) <= 80 for line in lines)
    kinds = {line.split()[0]: line for line in lines[1:]}
    assert "  boxes  " in kinds["boxtrack"] and "boxes + video" in kinds["deepsort"]
    assert "robot positions" in kinds["kalman_ha"] and "robot positions" in kinds["set"]
    assert compact_lines(["sort"], width=30)[1].endswith("…") and len(compact_lines(["sort"], width=30)[1]) == 30



def test_kernels_not_cached_compile_after_the_run_while_it_takes_the_numpy_path(monkeypatch, capsys):
    import types

    from lookalike import _compiled

    module = types.ModuleType("fake_kernels")
    started: list[object] = []
    monkeypatch.setattr(_compiled, "compile_aside", True)
    monkeypatch.setattr(_compiled, "kernels_cached", lambda m: False)
    monkeypatch.setattr(_compiled.atexit, "register", started.append)
    switch = _compiled.KernelSwitch("LOOKALIKE_TEST_FIRST_RUN", lambda: module, warm="fake_kernels:warm")
    assert switch.compiled() is None and len(started) == 1  # this run: the numpy path; the compile: at exit
    assert "not compiled yet" in capsys.readouterr().err
    switch.use_compiled(True)
    assert switch.compiled() is module  # forced on (as the tests of the kernels do): compiled here
    monkeypatch.setattr(_compiled, "kernels_cached", lambda m: True)
    switch.use_compiled(None)
    assert switch.compiled() is module and len(started) == 1
    monkeypatch.setattr(_compiled, "compile_aside", False)  # a library user: compiled in the process
    monkeypatch.setattr(_compiled, "kernels_cached", lambda m: False)
    assert switch.compiled() is module and len(started) == 1


def test_boxtrack_kernels_compile_once_with_one_line_then_load_from_the_cache(tmp_path):
    pytest.importorskip("numba")
    code = ("from lookalike import _compiled\nfrom lookalike.trackers.kernels import boxtrack as k\n"
            "before = _compiled.kernels_cached(k.module())\nk.warm()\n"
            "print('cached:', before, _compiled.kernels_cached(k.module()))")
    env = {**os.environ, "NUMBA_CACHE_DIR": str(tmp_path)}
    runs = [subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True, env=env)
            for _ in range(2)]
    assert runs[0].stdout.split() == ["cached:", "False", "True"] and runs[1].stdout.split() == ["cached:", "True",
                                                                                               "True"]
    assert runs[0].stderr.count("compiling the fast kernels once") == 1 and "compiling" not in runs[1].stderr


def test_warm_up_runs_a_throw_away_tracker_over_the_first_frames():
    from lookalike.loop import warm_up

    made: list[list[int]] = []

    class Counting:
        def __init__(self) -> None:
            self.seen: list[int] = []
            made.append(self.seen)

        def update(self, frame: int) -> list[int]:
            self.seen.append(frame)
            return []

    warm_up(Counting, iter(range(100)), n=4)
    assert made == [[0, 1, 2, 3]]
    warm_up(Counting, [7])
    assert made[1] == [7]


def test_identification_figures_do_not_change_with_the_warm_up():
    from lookalike.bench.ident import build_identifier, run_identifier
    from lookalike.eval import identification_success_rate
    from lookalike.loop import run
    from lookalike.sim import preset, simulate_robots
    from lookalike.trackers.parts.identity import labels_from_tracks

    seq = simulate_robots(preset("m3n2"), 40, 5)
    labels: list[object] = []
    run(build_identifier("kalman_ha2", seq), seq.frames(),
        lambda f, tracks: labels.append(labels_from_tracks(len(f.detections), tracks)))
    figures = run_identifier("kalman_ha2", [seq])
    assert figures["success"] == identification_success_rate(labels, seq.true_labels())
    assert figures["detections"] == sum(len(x) for x in labels)  # type: ignore[arg-type]


def test_blob_detection_shows_frames_done_of_the_declared_count():
    from lookalike.pipeline.blobs import steps
    from lookalike.pipeline.runner import Event

    events: list[Event] = []
    name = "detecting blobs in v.mp4"
    advance = steps(events.append)(name, 5)
    for _ in range(5):
        advance()
    assert events == [Event("start", name, 5), *[Event("advance", name, 1)] * 5, Event("end", name)]


@pytest.mark.parametrize("columns", ["80", "130"])
def test_help_without_a_command_lists_the_same_commands_without_importing_them(columns):
    env = {**os.environ, "COLUMNS": columns}
    script = subprocess.run([sys.executable, "-m", "lookalike", "--help"], capture_output=True, text=True, env=env,
                            check=True).stdout
    library = ("import sys\nfrom lookalike.cli import app\nsys.argv = ['lookalike', '--help']\n"
               "app(prog_name='lookalike')")
    every = subprocess.run([sys.executable, "-c", library], capture_output=True, text=True, env=env).stdout
    assert script.replace("python -m lookalike", "lookalike") == every and "trackers" in script and "bench" in script


def test_the_summaries_of_help_are_the_commands_own():
    from typer.main import get_command

    from lookalike.cli import MODULES, app
    from lookalike.cli.summaries import summaries

    group = get_command(app)
    assert {n: (c.help or "").split("\n\n")[0].strip() for n, c in group.commands.items()  # type: ignore[attr-defined]
            if not c.hidden} == summaries(MODULES)


def test_a_command_after_options_still_runs():
    out = subprocess.run([sys.executable, "-m", "lookalike", "trackers", "--names"], capture_output=True, text=True,
                         check=True).stdout
    assert "boxtrack" in out.split()


@pytest.mark.parametrize(("argv0", "expected"), [
    ("/usr/local/bin/lookalike", True),
    ("/x/src/lookalike/__main__.py", True),  # python -m lookalike
    ("/x/site-packages/pytest/__main__.py", False),  # python -m pytest: another module's __main__
    ("/x/bin/python", False),
])
def test_only_the_lookalike_program_counts_as_the_program(monkeypatch, argv0, expected):
    from lookalike.cli.program import run_as_program

    monkeypatch.setattr(sys, "argv", [argv0, "-q"])
    assert run_as_program() is expected


def test_commands_keep_their_options_under_python_m_pytest():
    """``python -m pytest -q`` (argv[0] pytest's ``__main__.py``, no command) must load the real commands."""
    code = ("import sys; sys.argv = ['/x/site-packages/pytest/__main__.py', '-q']\n"
            "from typer.testing import CliRunner\nfrom lookalike.cli import app\n"
            "r = CliRunner().invoke(app, ['eval', '--help'])\nprint('--gt' in r.output)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert out.stdout.strip() == "True", out.stdout + out.stderr
