"""The PyTorch device a training runs on, named by the user (``cpu``, ``cuda``, ``cuda:N`` or ``auto``)."""

from __future__ import annotations

from typing import Any

from lookalike._optional import needs


def torch_device(name: str) -> Any:
    """The ``torch.device`` of ``name`` (``auto``: cuda where PyTorch sees one, else cpu); ``ValueError`` naming it
    when PyTorch does not know it or sees no CUDA device for it."""
    with needs("torch"):
        import torch

    if name == "auto":
        name = "cuda" if torch.cuda.is_available() else "cpu"
    try:
        device = torch.device(name)
    except RuntimeError:
        raise ValueError(f"device {name!r}: choose cpu, cuda, cuda:N or auto") from None
    if device.type == "cuda" and not torch.cuda.is_available():
        raise ValueError(f"device {name!r}: this PyTorch sees no CUDA device (use cpu)")
    return device


__all__ = ["torch_device"]
