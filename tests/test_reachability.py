"""Every module of the package is reachable from a command or the public API, and the package never
imports the research code or the benchmark scripts.

The import graph is read from the source with ``ast`` (nothing is imported): ``import`` and
``from ... import`` statements anywhere in a module (lazy imports inside functions included, relative
ones resolved), plus string constants that name a lookalike module (``"lookalike.trackers.sort"``,
``"lookalike.trackers.lstm.tracker:LstmIdentifier"``), as the lazy ``_HOME`` tables and the tracker registry
use. Importing ``a.b.c`` also imports the packages ``a`` and ``a.b``. The roots are the command line
(every module of ``lookalike.cli``), ``python -m lookalike``, the package and every subpackage
``__init__`` (the public API), and the entry points in pyproject.toml.
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
SRC = ROOT / "src"
PACKAGE = "lookalike"


def _modules() -> dict[str, Path]:
    """Dotted module name -> file, for every ``.py`` under src/lookalike (a package is its ``__init__``)."""
    out = {}
    for path in sorted((SRC / PACKAGE).rglob("*.py")):
        parts = list(path.relative_to(SRC).with_suffix("").parts)
        if parts[-1] == "__init__":
            parts.pop()
        out[".".join(parts)] = path
    return out


MODULES = _modules()


def _resolve(name: str) -> str | None:
    """The longest module that ``name`` (a module, or a module's attribute) starts with, or None."""
    while name:
        if name in MODULES:
            return name
        name = name.rpartition(".")[0]
    return None


def _named(module: str, path: Path) -> set[str]:
    """Modules that ``module`` imports or names in a string constant."""
    package = module if path.name == "__init__.py" else module.rpartition(".")[0]
    names: set[str] = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"), str(path))):
        if isinstance(node, ast.Import):
            names.update(alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                parts = package.split(".")[: len(package.split(".")) - (node.level - 1)]
                base = ".".join(parts + ([node.module] if node.module else []))
            names.add(base)
            names.update(f"{base}.{alias.name}" for alias in node.names)  # a submodule, or an attribute
        elif isinstance(node, ast.Constant) and isinstance(node.value, str) \
                and node.value.startswith(PACKAGE + "."):
            names.add(node.value.split(":")[0])
    return {m for m in map(_resolve, names) if m is not None}


def _with_parents(modules: set[str]) -> set[str]:
    out = set(modules)
    for name in modules:
        while "." in name:
            name = name.rpartition(".")[0]
            out.add(name)
    return out


def _entry_points() -> set[str]:
    tomllib = pytest.importorskip("tomllib", reason="reading pyproject.toml needs Python 3.11's tomllib")
    project = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))["project"]
    targets = list(project.get("scripts", {}).values())
    for group in project.get("entry-points", {}).values():
        targets += group.values()
    return {target.split(":")[0] for target in targets}


def _roots() -> set[str]:
    cli = {m for m in MODULES if m == f"{PACKAGE}.cli" or m.startswith(f"{PACKAGE}.cli.")}
    packages = {m for m, path in MODULES.items() if path.name == "__init__.py"}
    return cli | packages | {f"{PACKAGE}.__main__"} | _entry_points()


def unreachable() -> list[str]:
    """Modules of the package that no root reaches, sorted."""
    edges = {m: _with_parents(_named(m, path)) for m, path in MODULES.items()}
    roots = _roots()
    missing = sorted(roots - set(MODULES))
    assert not missing, f"roots that are not modules of src/{PACKAGE}: {missing}"
    seen: set[str] = set()
    stack = list(roots)
    while stack:
        module = stack.pop()
        if module not in seen:
            seen.add(module)
            stack.extend(edges[module] - seen)
    return sorted(set(MODULES) - seen)


def test_the_graph_sees_lazy_imports_and_module_strings() -> None:
    edges = {m: _named(m, path) for m, path in MODULES.items()}
    assert f"{PACKAGE}.trackers.sort" in edges[f"{PACKAGE}.trackers.registry"]  # the registry's name table
    assert f"{PACKAGE}.io" in edges[PACKAGE]  # the public API's lazy _HOME table


def test_every_module_is_reachable_from_a_command_or_the_public_api() -> None:
    lost = unreachable()
    lines = [f"{m} ({MODULES[m].relative_to(ROOT)})" for m in lost]
    assert not lost, ("modules no command, public API or entry point reaches (move research code to research/, "
                      "benchmark helpers to benchmarks/, or delete them):\n  " + "\n  ".join(lines))


def test_the_package_never_imports_research_or_benchmark_scripts() -> None:
    outside = {"research", "benchmarks", "_common", "_peers", "_soak"}
    found = []
    for module, path in MODULES.items():
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.Import):
                names = [alias.name for alias in node.names]
            elif isinstance(node, ast.ImportFrom) and not node.level:
                names = [node.module or ""]
            else:
                continue
            found += [f"{module}: {n}" for n in names if n.split(".")[0] in outside]
    assert not found, found
