import subprocess
import sys

import lookalike


def test_public_api_is_pinned():
    # Changing the public API is a decision: update this list on purpose.
    assert sorted(lookalike.__all__) == sorted(
        [
            "Beacons",
            "Detections",
            "Frame",
            "Sort",
            "TrackSnapshot",
            "TrackStatus",
            "__version__",
            "find_sequences",
            "frames_from_table",
            "make_tracker",
            "read_mot",
            "tracker_names",
            "tracker_parameters",
            "tracks_to_rows",
            "write_mot",
        ]
    )
    for name in lookalike.__all__:
        assert hasattr(lookalike, name), name


def test_import_needs_neither_torch_nor_opencv():
    code = ("import sys, lookalike, lookalike.trackers, lookalike.io; "
            "print('torch' in sys.modules, 'cv2' in sys.modules)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.split() == ["False", "False"]


def test_layers_import_downwards_only():
    from importlinter.cli import lint_imports

    assert lint_imports(config_filename="pyproject.toml") == 0
