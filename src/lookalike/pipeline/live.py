"""A live camera or stream checked before it is opened (``lookalike track --video 0|URL``)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from lookalike.io.needs import input_kind


def live_settings(spec: str, output: Path, tracker_name: str, detector: str, settings: list[str],
                  refused: dict[str, bool]) -> dict[str, Any]:
    """The blob detector's ``KEY=VALUE`` ``settings`` as values (none for an ONNX ``detector``); ``ValueError`` for
    options that do not apply to a live source (``refused``: name -> given), a tracker reading more than boxes, a
    folder as ``output`` or a detector that is neither ``blob`` nor an existing ``.onnx`` file."""
    given = [name for name, on in refused.items() if on]
    if given:
        raise ValueError(f"--video {spec}: a live source; drop {', '.join(given)} (see the live camera how-to)")
    if input_kind(tracker_name) != "boxes":
        raise ValueError(f"--video {spec}: a live source runs trackers that read boxes alone (boxtrack, sort), not "
                         f"{tracker_name!r}")
    if output.is_dir():
        raise ValueError(f"-o/--output: {output} is a folder; give a result file such as tracks.txt")
    if detector == "blob":
        from lookalike.viz.blob_video import blob_settings

        return blob_settings(settings)
    if not detector.lower().endswith(".onnx"):
        raise ValueError(f"--detector: choose blob or FILE.onnx, got {detector!r}")
    if not Path(detector).is_file():
        raise ValueError(f"--detector: {detector} does not exist")
    return {}


__all__ = ["live_settings"]
