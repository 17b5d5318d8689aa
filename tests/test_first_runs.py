"""First runs: what ``lookalike --help`` imports, the compact tracker listing, the message when numba compiles."""

from __future__ import annotations

import subprocess
import sys


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

