"""Optional packages: every import of one goes through :func:`needs`, which turns a missing package into
:class:`MissingExtra`, one line naming the extra of ``pyproject.toml`` that installs it and how to install it
here (from the wheel or the source folder lookalike was installed from)."""

from __future__ import annotations

import json
import sys
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

OPTIONAL: dict[str, tuple[str, str]] = {
    "cv2": ("vision", "OpenCV"),
    "sklearn": ("vision", "scikit-learn"),
    "onnxruntime": ("vision", "ONNX Runtime"),
    "matplotlib": ("viz", "matplotlib"),
    "av": ("viz", "PyAV"),
    "numba": ("fast", "numba"),
    "torch": ("train", "PyTorch"),
    "optuna": ("tune", "Optuna"),
    "rerun": ("rerun", "the Rerun SDK"),
    "ray": ("ray", "Ray"),
    "cyclonedds": ("ros", "Cyclone DDS"),
    "rosbags": ("ros", "rosbags"),
    "jsonschema": ("test", "jsonschema"),
}
"""Top-level module name → (extra that installs it, what it is called)."""


class MissingExtra(ModuleNotFoundError):
    """An optional package is not installed (or does not import); ``str()`` is one line naming the extra."""

    def __init__(self, module: str, detail: str = "") -> None:
        self.module = module
        self.extra, self.label = OPTIONAL[module]
        self.detail = detail
        broken = f" ({module} is installed but does not import: {detail})" if detail else ""
        super().__init__(f"needs {self.label} ({module}){broken}; install the '{self.extra}' extra: "
                         f"{install_command(self.extra)}", name=module)

    def __reduce__(self) -> tuple[type[MissingExtra], tuple[str, str]]:  # crosses process pools intact
        return MissingExtra, (self.module, self.detail)


def _installed_from() -> tuple[str, bool] | None:
    """Where lookalike was installed from (a wheel or a folder) and whether editable; None when unknown."""
    from importlib import metadata
    from urllib.parse import unquote, urlparse

    try:
        text = metadata.distribution("lookalike").read_text("direct_url.json")
        info = json.loads(text) if text else None
    except (metadata.PackageNotFoundError, ValueError, OSError):
        return None
    if not isinstance(info, dict) or not str(info.get("url", "")).startswith("file://"):
        return None
    editable = bool((info.get("dir_info") or {}).get("editable"))
    return unquote(urlparse(info["url"]).path), editable


def install_command(extra: str) -> str:
    """The pip command that installs ``extra`` into this Python from the wheel or folder lookalike was installed from
    (``-e`` if editable), else a placeholder for them (lookalike is not on PyPI)."""
    import shutil

    found = _installed_from()
    where, editable = found if found is not None else ("<lookalike wheel or source folder>", False)
    bin_dir = Path(sys.prefix) / "bin"
    pip = "pip" if Path(sys.executable).parent == bin_dir and Path(shutil.which("pip") or "/").resolve().parent == \
        bin_dir.resolve() else f"{sys.executable} -m pip"  # (the pip first on PATH is this environment's)
    return f"{pip} install {'-e ' if editable else ''}'{where}[{extra}]'"


@contextmanager
def needs(module: str) -> Iterator[None]:
    """``with needs("cv2"): import cv2``: a missing or broken optional package (a key of :data:`OPTIONAL`) raises
    :class:`MissingExtra` (an ``ImportError``)."""
    if module not in OPTIONAL:
        raise KeyError(f"{module!r} is not an optional package of lookalike ({', '.join(OPTIONAL)})")
    try:
        yield
    except MissingExtra:
        raise
    except ImportError as exc:
        if isinstance(exc, ModuleNotFoundError) and (exc.name or "").split(".")[0] == module:
            raise MissingExtra(module) from None
        # installed but broken: a package or shared library it needs is missing
        raise MissingExtra(module, " ".join(str(exc).split())[:160]) from None


__all__ = ["OPTIONAL", "MissingExtra", "install_command", "needs"]
