"""Opening an ONNX model with onnxruntime on the CPU, for the detectors and appearance models."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from lookalike._optional import needs


def open_session(path: Path, threads: int, what: str) -> Any:
    """An onnxruntime CPU ``InferenceSession`` of ``path`` with ``threads`` threads; ``FileNotFoundError`` when
    missing, ``ValueError`` when it cannot load (``what``: the kind of model, for the message)."""
    with needs("onnxruntime"):
        import onnxruntime as ort  # type: ignore[import-untyped]

    if not path.is_file():
        raise FileNotFoundError(f"{path}: no such {what}")
    options = ort.SessionOptions()
    options.intra_op_num_threads = threads
    options.inter_op_num_threads = 1
    options.log_severity_level = 3
    try:
        return ort.InferenceSession(str(path), options, providers=["CPUExecutionProvider"])
    except Exception as exc:  # onnxruntime raises its own exception types
        raise ValueError(f"{path}: not a loadable ONNX model ({str(exc).splitlines()[0]})") from None


def check_image_input(path: Path, model_input: Any, what: str, feeds: str) -> None:
    """``ValueError`` naming ``path`` unless ``model_input`` (an onnxruntime input, NCHW) takes 3 channels of float
    (``what``: the input's name in the message, ``feeds``: what lookalike gives it)."""
    channels = model_input.shape[1]
    if isinstance(channels, int) and channels != 3:
        raise ValueError(f"{path}: the {what} input has {channels} channel(s) {model_input.shape}; lookalike feeds 3 "
                         f"({feeds})")
    if model_input.type != "tensor(float)":
        raise ValueError(f"{path}: the {what} input is {model_input.type}; lookalike feeds tensor(float) ({feeds})")
