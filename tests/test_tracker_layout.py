"""The trackers package's layout: every tracker module sits under the independence contract (trackers are
compositions of shared parts, never forks of one another), and the shared parts, compiled kernels and
offline processing live in their own subpackages."""

from __future__ import annotations

from pathlib import Path

import pytest

tomllib = pytest.importorskip("tomllib", reason="reading pyproject.toml needs Python 3.11's tomllib")
ROOT = Path(__file__).resolve().parents[1]
TRACKERS = ROOT / "src" / "lookalike" / "trackers"


def _independent_modules() -> list[str]:
    contracts = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["importlinter"]["contracts"]
    return [m for c in contracts if c["type"] == "independence" for m in c["modules"]]


def _module(path: Path) -> str:
    parts = path.relative_to(ROOT / "src").with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def test_every_registered_tracker_is_under_the_independence_contract() -> None:
    listed = _independent_modules()
    registering = [_module(p) for p in TRACKERS.rglob("*.py") if "@register_tracker(" in p.read_text()]
    assert registering, "no module registers a tracker"
    for module in registering:
        assert any(module == m or module.startswith(m + ".") for m in listed), (
            f"{module} registers a tracker but is not in the independence contract")


def test_the_offline_closed_set_is_independent_of_the_online_trackers() -> None:
    assert "lookalike.trackers.offline" in _independent_modules()


def test_parts_kernels_and_offline_are_separate_subpackages() -> None:
    top = {p.stem for p in TRACKERS.glob("*.py")} - {"__init__", "base", "registry"}
    for name in top:
        text = (TRACKERS / f"{name}.py").read_text()
        is_tracker = "@register_tracker(" in text or name.endswith("_config")
        assert is_tracker, f"trackers/{name}.py is neither a tracker nor a tracker's config: move it to a subpackage"
    for sub in ("parts", "kernels", "offline"):
        assert (TRACKERS / sub / "__init__.py").exists()
    compiled = [p.name for p in (TRACKERS / "parts").rglob("*.py") if "import numba" in p.read_text()]
    assert not compiled, f"compiled code belongs in trackers/kernels/, not in parts: {compiled}"


def test_each_tracker_declares_what_it_needs_beyond_boxes(monkeypatch: pytest.MonkeyPatch) -> None:
    from dataclasses import dataclass

    from lookalike.io.needs import box_input_problem, input_kind
    from lookalike.trackers import registry
    from lookalike.trackers.base import NEEDS_APPEARANCE, NEEDS_ROBOTS

    kinds = {name: input_kind(name) for name in registry.tracker_names()}
    assert {n for n, k in kinds.items() if k == "boxes + video"} == {"deepsort", "diversort"}
    assert {n for n, k in kinds.items() if k == "robot positions"} >= {"kalman_ha", "kalman_ha2", "jpda", "lstm", "set"}
    assert {"sort", "boxtrack"} <= {n for n, k in kinds.items() if k == "boxes"}
    for name in kinds:
        assert getattr(registry.tracker_class(name), "needs", None) in (None, NEEDS_APPEARANCE, NEEDS_ROBOTS)

    monkeypatch.setattr(registry, "_REGISTRY", dict(registry._REGISTRY))  # (the test tracker goes with the test)

    @registry.register_tracker("test-needs-pixels")
    class Pixels:  # a tracker of one's own that reads appearance features says so the same way
        needs = NEEDS_APPEARANCE

        @dataclass(frozen=True)
        class Config:
            pass

    assert input_kind("test-needs-pixels") == "boxes + video"
    assert box_input_problem("test-needs-pixels", video=True) is None
    assert "--video" in (box_input_problem("test-needs-pixels") or "")


def test_a_tracker_of_ones_own_cannot_take_a_built_in_name(monkeypatch) -> None:
    """Registered before the built-in module was imported, it used to win, and importing that module later (any
    lookup of an unknown name imports them all) failed with 'already registered'."""
    from dataclasses import dataclass

    from lookalike.trackers import registry

    monkeypatch.setattr(registry, "_REGISTRY", {k: v for k, v in registry._REGISTRY.items() if k != "jpda"})
    with pytest.raises(ValueError, match="'jpda' is the name of a built-in tracker; register Mine under another"):

        @registry.register_tracker("jpda")
        class Mine:
            @dataclass(frozen=True)
            class Config:
                pass

    assert "jpda" not in registry._REGISTRY  # (refused: the built-in one registers when its module is imported)
