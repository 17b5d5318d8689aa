"""The package: ``python -m build`` makes a wheel and an sdist holding the shipped models, schema and presets; the
user extras hold no developer tools; ``make demo`` installs only what the demo needs; the version has a changelog
entry; the docs install from the wheel or the repository, never from PyPI (lookalike is not published there)."""

from __future__ import annotations

import re
import subprocess
import sys
import tarfile
import tomllib
import zipfile
from pathlib import Path

import pytest

import lookalike

ROOT = Path(__file__).resolve().parents[1]
PYPROJECT = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))
PROJECT = PYPROJECT["project"]
VERSION = lookalike.__version__  # pyproject.toml reads it from lookalike/_version.py (its version is dynamic)
EXTRAS: dict[str, list[str]] = PROJECT["optional-dependencies"]
USER_EXTRAS = ("vision", "viz", "fast", "train", "tune", "rerun", "ray")
DEVELOPER_TOOLS = ("pytest", "hypothesis", "mypy", "ruff", "import-linter", "mkdocs", "playwright", "build")
SHIPPED = [  # package data the commands read at run time (paths inside the wheel)
    "lookalike/py.typed",
    "lookalike/io/results.schema.json",
    "lookalike/bench/presets/boxtrack.json",
    "lookalike/trackers/lstm/weights_data/lstm_m3_n2.npz",
    "lookalike/trackers/set/weights/set_any.npz",
    "lookalike/vision/models_data/diver_reid.onnx",
    "lookalike/vision/models_data/robot_detector.npz",
    "lookalike/viz/label/static/index.html",
]
DOCS = [ROOT / "README.md", *sorted((ROOT / "docs").rglob("*.md"))]


def _name(requirement: str) -> str:
    return re.split(r"[\s<>=!~\[;]", requirement, maxsplit=1)[0].lower()


def test_user_extras_hold_no_developer_tools() -> None:
    for extra in USER_EXTRAS:
        names = {_name(r) for r in EXTRAS[extra]}
        assert not names & set(DEVELOPER_TOOLS), f"extra {extra!r} holds developer tools {names & set(DEVELOPER_TOOLS)}"
    dev = " ".join(EXTRAS["dev"])
    for part in ("test", "lint", "docs", "browser", "build", *[e for e in USER_EXTRAS if e not in ("rerun", "ray")]):
        assert part in dev, f"the dev extra misses {part}"


def test_make_demo_installs_the_demo_extras_only() -> None:
    makefile = (ROOT / "Makefile").read_text(encoding="utf-8")
    assert re.search(r"^DEMO_EXTRAS := vision,viz$", makefile, flags=re.M)
    assert re.search(r"^demo: \$\(DEMO_STAMP\)$", makefile, flags=re.M)
    assert re.search(r"^EXTRAS \?= dev$", makefile, flags=re.M)  # make test, lint, docs: the dev extra


def test_the_version_has_a_changelog_entry() -> None:
    changelog = (ROOT / "CHANGELOG.md").read_text(encoding="utf-8")
    first = re.search(r"^## (\S+)", changelog, flags=re.M)
    assert first is not None and first.group(1) == VERSION


def test_one_version_everywhere() -> None:
    from importlib.metadata import version

    from lookalike.io.results import lookalike_version

    assert PROJECT["dynamic"] == ["version"] and PYPROJECT["tool"]["setuptools"]["dynamic"]["version"] == {
        "attr": "lookalike._version.__version__"}
    assert version("lookalike") == lookalike_version() == VERSION  # (the environment was installed from here)


def test_docs_never_install_from_pypi() -> None:
    """``pip install 'lookalike[...]'`` (or ``pip install lookalike``) cannot work: lookalike is not on PyPI."""
    for doc in DOCS:
        text = doc.read_text(encoding="utf-8")
        for match in re.finditer(r"pip install[^\n`]*", text):
            line = match.group(0)
            assert not re.search(r"""(^|\s)['"]?lookalike(\[|['"\s]|$)""", line.split("pip install", 1)[1]), \
                f"{doc.relative_to(ROOT)}: {line!r}"


@pytest.fixture(scope="module")
def dist(tmp_path_factory: pytest.TempPathFactory) -> Path:
    pytest.importorskip("build", reason="the 'build' package (dev extra) makes the wheel")
    out = tmp_path_factory.mktemp("dist")
    result = subprocess.run([sys.executable, "-m", "build", "--no-isolation", "--outdir", str(out), str(ROOT)],
                            capture_output=True, text=True, timeout=600)
    assert result.returncode == 0, result.stdout[-2000:] + result.stderr[-2000:]
    return out


def test_wheel_and_sdist_hold_the_shipped_files(dist: Path) -> None:
    version = VERSION
    wheel = dist / f"lookalike-{version}-py3-none-any.whl"
    sdist = dist / f"lookalike-{version}.tar.gz"
    assert wheel.is_file() and sdist.is_file(), sorted(p.name for p in dist.iterdir())
    names = set(zipfile.ZipFile(wheel).namelist())
    assert not [n for n in names if "__pycache__" in n or n.endswith(".pyc")]
    assert not [n for n in names if n.startswith(("tests/", "research/", "benchmarks/"))]
    for path in SHIPPED:
        assert path in names, f"{path} is not in the wheel"
    metadata = zipfile.ZipFile(wheel).read(f"lookalike-{version}.dist-info/METADATA").decode()
    assert f"\nVersion: {version}\n" in metadata
    for extra in (*USER_EXTRAS, "dev"):
        assert f"Provides-Extra: {extra}" in metadata
    with tarfile.open(sdist) as tar:
        members = {m.split("/", 1)[1] for m in tar.getnames() if "/" in m}
    for path in [*SHIPPED, "CHANGELOG.md", "constraints.txt", "LICENSE", "README.md", "pyproject.toml"]:
        assert (f"src/{path}" if path.startswith("lookalike/") else path) in members, f"{path} is not in the sdist"
