"""Static checks that a test run also sees: ruff clean, and tracker plugins declared where the import
contracts can see them (``make lint`` also runs mypy and lint-imports)."""

from __future__ import annotations

import shutil
import subprocess
import sys
from importlib.metadata import entry_points
from pathlib import Path

import pytest

from lookalike.trackers import registry

tomllib = pytest.importorskip("tomllib", reason="reading pyproject.toml needs Python 3.11's tomllib")
ROOT = Path(__file__).resolve().parents[1]
PYPROJECT = tomllib.loads((ROOT / "pyproject.toml").read_text())
PLUGINS: dict[str, str] = PYPROJECT["project"]["entry-points"]["lookalike.trackers"]


def _layer_index(module: str) -> int:
    """Position of ``module`` in the layers contract (0: top), or -1 when no layer holds it."""
    contract = next(c for c in PYPROJECT["tool"]["importlinter"]["contracts"] if c["type"] == "layers")
    for i, layer in enumerate(contract["layers"]):
        for part in layer.replace(":", "|").split("|"):
            name = part.strip().strip("()")
            if module == name or module.startswith(name + "."):
                return i
    return -1


def test_tracker_plugins_sit_above_the_trackers_layer() -> None:
    trackers = _layer_index("lookalike.trackers")
    assert PLUGINS, "no [project.entry-points.\"lookalike.trackers\"] in pyproject.toml"
    for name, target in PLUGINS.items():
        module = target.split(":")[0]
        assert 0 <= _layer_index(module) < trackers, f"plugin {name}: {module} is not in a layer above the trackers"


def test_tracker_plugins_register_under_their_entry_point_name() -> None:
    for name, target in PLUGINS.items():
        module, _, attr = target.partition(":")
        cls = getattr(__import__(module, fromlist=[attr]), attr)
        assert registry.tracker_class(name) is cls


def test_the_registry_loads_exactly_the_declared_plugins() -> None:
    declared = {target.split(":")[0] for target in PLUGINS.values()}
    listed = getattr(registry, "PLUGIN_MODULES", None)
    if listed is not None:  # the string list the registry imports, until it reads the entry points
        assert set(listed) == declared
    installed = {ep.name: ep.value for ep in entry_points(group="lookalike.trackers")}
    if not installed:
        pytest.skip("the installed metadata predates the entry point (reinstall: make venv)")
    assert installed == PLUGINS


def test_ruff_is_clean() -> None:
    ruff = shutil.which("ruff", path=str(Path(sys.executable).parent)) or shutil.which("ruff")
    if ruff is None:
        pytest.skip("ruff is not installed (the 'test' extra has it)")
    result = subprocess.run([ruff, "check", "--no-cache", "src", "tests", "benchmarks", "research"], cwd=ROOT,
                            capture_output=True, text=True)
    assert result.returncode == 0, result.stdout + result.stderr
