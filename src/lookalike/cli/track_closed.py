"""The ``--targets N --offline`` closed set of a blob or ONNX detector's boxes in ``lookalike track``, printed; the
work is :mod:`lookalike.pipeline.closed`."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from lookalike.cli.app import failing
from lookalike.cli.progress import printed_events
from lookalike.pipeline import closed


def check_result_file(output: Path, video: Path | None = None) -> None:
    """Fail unless ``output`` can be the ``--video`` branch's result file and ``video`` (if given) exists."""
    from lookalike.pipeline.video import check_result_file as check

    with failing(ValueError):
        check(output, video)


def offline_video(det: np.ndarray, output: Path, n_targets: int, params: dict[str, Any], frame_rate: float,
                  n_frames: int | None, min_score: float, **options: Any) -> None:
    """:func:`lookalike.pipeline.closed.offline_video` (given ``options``), printed."""
    with failing(ValueError), printed_events("boxtrack") as on_event:
        closed.offline_video(det, output, n_targets, params, frame_rate, n_frames, min_score, on_event, **options)


__all__ = ["check_result_file", "offline_video"]
