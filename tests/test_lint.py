"""Static checks that a test run also sees: ruff clean, and tracker plugins declared where the import
contracts can see them (``make lint`` also runs mypy and lint-imports)."""

from __future__ import annotations

import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from lookalike.trackers import registry

tomllib = pytest.importorskip("tomllib", reason="reading pyproject.toml needs Python 3.11's tomllib")
ROOT = Path(__file__).resolve().parents[1]
PYPROJECT = tomllib.loads((ROOT / "pyproject.toml").read_text())
PLUGINS: dict[str, str] = PYPROJECT["project"].get("entry-points", {}).get("lookalike.trackers", {})


def test_every_shipped_tracker_is_built_in() -> None:
    """The package declares no tracker plugins: every shipped tracker sits in the trackers layer (the
    entry-point group stays open to other packages' trackers)."""
    assert PLUGINS == {}
    for name, module in registry.BUILTIN_TRACKERS.items():
        assert module.startswith("lookalike.trackers."), f"{name}: {module}"
        assert registry.tracker_class(name).__module__ == module


def test_a_third_party_plugin_registers_under_its_entry_point_name(monkeypatch: pytest.MonkeyPatch,
                                                                    tmp_path: Path) -> None:
    import sys

    (tmp_path / "lookalike_test_plugin.py").write_text(
        "from dataclasses import dataclass\n\n"
        "from lookalike.trackers.registry import register_tracker\n\n\n"
        "@register_tracker('test-plugin')\n"
        "class TestPlugin:\n"
        "    @dataclass(frozen=True)\n"
        "    class Config:\n"
        "        pass\n"
    )
    monkeypatch.syspath_prepend(str(tmp_path))
    monkeypatch.setattr(registry, "_REGISTRY", dict(registry._REGISTRY))  # (undone after the test)
    monkeypatch.setattr(registry, "_plugins", {"test-plugin": "lookalike_test_plugin"})
    try:
        assert "test-plugin" in registry.tracker_names()
        cls = registry.tracker_class("test-plugin")
        assert cls.__module__ == "lookalike_test_plugin" and cls.__name__ == "TestPlugin"
    finally:
        sys.modules.pop("lookalike_test_plugin", None)


def test_ruff_is_clean() -> None:
    ruff = shutil.which("ruff", path=str(Path(sys.executable).parent)) or shutil.which("ruff")
    if ruff is None:
        pytest.skip("ruff is not installed (the 'test' extra has it)")
    result = subprocess.run([ruff, "check", "--no-cache", "src", "tests", "benchmarks", "research"], cwd=ROOT,
                            capture_output=True, text=True)
    assert result.returncode == 0, result.stdout + result.stderr
