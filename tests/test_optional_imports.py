"""Optional packages: each one hidden in turn (a ``sys.meta_path`` finder that refuses it, as if it were not
installed), every command module imports and shows its help, and the commands that need the package end
with one error line naming the extra to install (exit 2, no traceback). Every import of an optional package in
src/ goes through :func:`lookalike._optional.needs`."""

from __future__ import annotations

import ast
import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from lookalike._optional import OPTIONAL, MissingExtra, install_command, needs

ROOT = Path(__file__).resolve().parents[1]
SRC = ROOT / "src" / "lookalike"
DATA = ROOT.parent / "shared" / "data"
MOT17 = DATA / "mot17_mini" / "MOT17-02-FRCNN"

_PREAMBLE = """
import sys

class _Hidden:
    def find_spec(self, name, path=None, target=None):
        if name.split(".")[0] in {hidden!r}:
            raise ModuleNotFoundError(f"No module named {{name!r}}", name=name)
        return None

sys.meta_path.insert(0, _Hidden())
"""


def _run(code: str, hidden: list[str], cwd: Path, timeout: float = 300) -> subprocess.CompletedProcess[str]:
    env = {**os.environ, "OMP_NUM_THREADS": "1", "COLUMNS": "200"}
    return subprocess.run([sys.executable, "-c", _PREAMBLE.format(hidden=hidden) + code], cwd=cwd, env=env,
                          capture_output=True, text=True, timeout=timeout)


def _lookalike(args: list[str], hidden: list[str], cwd: Path) -> subprocess.CompletedProcess[str]:
    """``lookalike ARGS`` as the script runs it, with the ``hidden`` packages missing."""
    code = f"sys.argv = ['lookalike', *{args!r}]\nfrom lookalike.cli import main\nmain()\n"
    return _run(code, hidden, cwd)


def _imports(tree: ast.AST) -> list[tuple[ast.stmt, str]]:
    found: list[tuple[ast.stmt, str]] = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            found += [(node, alias.name.split(".")[0]) for alias in node.names]
        elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
            found.append((node, node.module.split(".")[0]))
    return found


def test_every_optional_import_goes_through_needs() -> None:
    """Each ``import`` of an optional package in src/ sits in a ``with needs("<that package>"):`` block."""
    missing = []
    for path in sorted(SRC.rglob("*.py")):
        tree = ast.parse(path.read_text(encoding="utf-8"))
        guarded: dict[int, str] = {}
        for node in ast.walk(tree):
            if isinstance(node, ast.With) and len(node.items) == 1:
                call = node.items[0].context_expr
                if (isinstance(call, ast.Call) and isinstance(call.func, ast.Name) and call.func.id == "needs"
                        and call.args and isinstance(call.args[0], ast.Constant)):
                    guarded.update({id(stmt): str(call.args[0].value) for stmt in node.body})
        for stmt, top in _imports(tree):
            if top in OPTIONAL and guarded.get(id(stmt)) != top and path.name != "_optional.py":
                missing.append(f"{path.relative_to(ROOT)}:{stmt.lineno}: import of {top}")
    assert not missing, "\n".join(missing)


def test_needs_names_the_extra_in_one_line() -> None:
    with pytest.raises(MissingExtra) as caught, needs("optuna"):
        raise ModuleNotFoundError("No module named 'optuna'", name="optuna")
    message = str(caught.value)
    assert "\n" not in message and "'tune' extra" in message and "[tune]" in message
    assert isinstance(caught.value, ImportError)  # code that falls back without the package keeps working
    with pytest.raises(ModuleNotFoundError) as other, needs("cv2"):
        raise ModuleNotFoundError("No module named 'numpy'", name="numpy")
    assert "installed but does not import" in str(other.value)  # cv2 is there but broken
    with pytest.raises(KeyError):
        with needs("numpy"):
            pass


def test_install_command_points_at_where_lookalike_came_from() -> None:
    """Never ``pip install 'lookalike[...]'`` (not on PyPI): the wheel or folder it was installed from."""
    command = install_command("viz")
    assert "[viz]'" in command and "'lookalike[" not in command
    from importlib import metadata

    direct = json.loads(metadata.distribution("lookalike").read_text("direct_url.json") or "{}")
    if (direct.get("dir_info") or {}).get("editable"):
        assert " -e " in command and str(ROOT) in command


@pytest.mark.parametrize("hidden", sorted(OPTIONAL))
def test_every_command_imports_and_helps_without(hidden: str, tmp_path: Path) -> None:
    """With ``hidden`` missing, every command module imports and every command (and sub-command) prints its help."""
    code = """
from typer.testing import CliRunner
import typer.main
import lookalike.cli as cli
group = typer.main.get_command(cli.app)
runner = CliRunner()
bad = []
def walk(command, path):
    result = runner.invoke(cli.app, [*path, "--help"])
    if result.exit_code != 0 or result.exception is not None:
        bad.append((path, result.exit_code, repr(result.exception), result.output[-300:]))
    for name in sorted(getattr(command, "commands", {}) or {}):
        walk(command.commands[name], [*path, name])
walk(group, [])
print("BAD", bad)
"""
    result = _run(code, [hidden], tmp_path)
    assert result.returncode == 0, result.stderr[-2000:]
    assert "BAD []" in result.stdout, result.stdout[-3000:]


def _cases() -> list[tuple[str, list[str], str]]:
    """(hidden package, command line, extra named); each command needs the package."""
    video = ["--video", str(MOT17 / "img1"), "--detections", str(MOT17 / "det" / "det.txt"), "-o", "t.txt"]
    return [
        ("cv2", ["track", "-t", "boxtrack", *video], "vision"),
        ("cv2", ["track", "--video", "v.mp4", "--detector", "blob", "-o", "t.txt"], "vision"),
        ("cv2", ["render", "--video", str(MOT17 / "img1"), "--tracks", str(MOT17 / "det" / "det.txt"),
                 "-o", "r.mp4"], "vision"),
        ("cv2", ["render-robots", "sim.jsonl", "-o", "r.mp4"], "vision"),
        ("cv2", ["demo", "--quick", "-o", "demo"], "vision"),
        ("matplotlib", ["demo", "--quick", "-o", "demo"], "viz"),
        ("onnxruntime", ["track", "-t", "deepsort", "--features", "learned", *video], "vision"),
        ("sklearn", ["train-heading", "-o", "heading.npz"], "vision"),
        ("sklearn", ["train-detector", "-o", "detector.npz"], "vision"),
        ("optuna", ["tune", "-t", "boxtrack", str(DATA / "mot15" / "TUD-Campus"), "-o", "p.json"], "tune"),
        ("rerun", ["demo", "--quick", "-o", "demo", "--rerun-save", "d.rrd"], "rerun"),
        ("ray", ["tune", "-t", "boxtrack", str(DATA / "mot15" / "TUD-Campus"), "-o", "p.json", "--backend", "ray"],
         "ray"),
        ("torch", ["train", "-o", "runs"], "train"),
        ("torch", ["train-appearance", "-o", "runs"], "train"),
        ("onnxruntime", ["train-appearance", "-o", "runs"], "vision"),
        ("cyclonedds", ["serve", "-t", "set", "--transport", "dds", "--duration", "1"], "ros"),
        ("rosbags", ["simulate", "--frames", "3", "--bag", "-o", "sims"], "ros"),
        ("rosbags", ["track", "--bag", "run", "--camera-topic", "/c", "-t", "set", "-o", "t.txt"], "ros"),
    ]


@pytest.mark.skipif(not MOT17.is_dir(), reason="needs ../shared/data")
@pytest.mark.parametrize(("hidden", "args", "extra"), _cases(), ids=lambda v: v if isinstance(v, str) else None)
def test_a_command_without_its_package_names_the_extra(hidden: str, args: list[str], extra: str,
                                                       tmp_path: Path) -> None:
    if args[0] == "render-robots":
        made = _lookalike(["simulate", "--preset", "m3n2", "--frames", "5", "-o", "sims"], [], tmp_path)
        assert made.returncode == 0, made.stderr
        args = [args[0], str(next((tmp_path / "sims").glob("*.jsonl"))), *args[2:]]
    if args[0] == "track" and "v.mp4" in args:
        (tmp_path / "v.mp4").write_bytes(b"")
    before = set(tmp_path.rglob("*"))
    result = _lookalike(args, [hidden], tmp_path)
    lines = [ln for ln in result.stderr.splitlines() if ln.strip()]
    assert result.returncode == 2, result.stderr[-2000:]
    assert not result.stdout.strip(), result.stdout[-2000:]  # it stops before any work or output ...
    assert set(tmp_path.rglob("*")) == before  # ... and leaves no file or folder behind
    assert "Traceback" not in result.stderr and len(lines) == 1, result.stderr[-2000:]
    named = "--rerun-save: needs" if "--rerun-save" in args else f"lookalike {args[0]}: needs"  # (names its option)
    assert named in lines[0] and f"'{extra}' extra" in lines[0] and f"[{extra}]'" in lines[0]


def test_train_appearance_without_onnx_stops_before_training(tmp_path: Path) -> None:
    """torch exports ONNX only with the onnx package: without it the command trained (18 minutes by default), then
    ended in torch's 'Module onnx is not installed!' with nothing written."""
    result = _lookalike(["train-appearance", "-o", "runs"], ["onnx"], tmp_path)
    lines = [ln for ln in result.stderr.splitlines() if ln.strip()]
    assert result.returncode == 2 and not result.stdout.strip(), result.stderr[-2000:]
    assert len(lines) == 1 and "needs the onnx package" in lines[0] and "pip install" in lines[0], result.stderr
    assert not (tmp_path / "runs").exists()
