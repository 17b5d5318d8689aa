"""Every benchmark script (``benchmarks/[a-z]*.py``, run by ``make bench`` only) still starts: its ``--help`` exits 0
with a usage line, so a renamed import or a module-level error breaks the tests, not the next ``make bench``. The
scripts run one after another in one process (the library imported once). (Imports made inside a script's ``main``
after its arguments are parsed are not reached.)"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

BENCHMARKS = Path(__file__).resolve().parents[1] / "benchmarks"

_HELP_EACH = """
import contextlib, io, runpy, sys
sys.path.insert(0, sys.argv[1])  # (each script imports its helpers from its own folder)
for path in sys.argv[2:]:
    sys.argv, out = [path, "--help"], io.StringIO()
    try:
        with contextlib.redirect_stdout(out):
            runpy.run_path(path, run_name="__main__")
        print(f"{path}: --help did not exit")
    except SystemExit as exc:
        if exc.code not in (0, None) or "usage:" not in out.getvalue():
            print(f"{path}: --help exited {exc.code}")
    except BaseException as exc:
        print(f"{path}: {type(exc).__name__}: {exc}")
"""


def test_every_benchmark_script_starts() -> None:
    scripts = sorted(BENCHMARKS.glob("[a-z]*.py"))
    assert scripts, f"no scripts in {BENCHMARKS}"
    without = [s.name for s in scripts if "argparse" not in s.read_text(encoding="utf-8")]
    assert not without, f"benchmark scripts without argparse (no --help to check): {without}"
    proc = subprocess.run([sys.executable, "-c", _HELP_EACH, str(BENCHMARKS), *map(str, scripts)],
                          cwd=BENCHMARKS.parent, capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0 and not proc.stdout.strip(), proc.stdout[-3000:] + proc.stderr[-3000:]
