"""Every benchmark script (``benchmarks/[a-z]*.py``, run by ``make bench`` only) still starts: its ``--help`` exits 0
with a usage line, so a renamed import or a module-level error breaks the tests, not the next ``make bench``. Scripts
without argparse are skipped. (Imports made inside a script's ``main`` after its arguments are parsed are not
reached.)"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

BENCHMARKS = Path(__file__).resolve().parents[1] / "benchmarks"
SCRIPTS = sorted(BENCHMARKS.glob("[a-z]*.py"))


def test_there_are_benchmark_scripts() -> None:
    assert SCRIPTS, f"no scripts in {BENCHMARKS}"


@pytest.mark.parametrize("script", SCRIPTS, ids=[s.stem for s in SCRIPTS])
def test_benchmark_script_help_runs(script: Path) -> None:
    if "argparse" not in script.read_text(encoding="utf-8"):
        pytest.skip(f"{script.name} has no argparse")
    proc = subprocess.run([sys.executable, str(script), "--help"], cwd=BENCHMARKS.parent, capture_output=True,
                          text=True, timeout=120)
    assert proc.returncode == 0, f"{script.name} --help exited {proc.returncode}:\n{proc.stderr[-3000:]}"
    assert "usage:" in proc.stdout, proc.stdout[-2000:]
