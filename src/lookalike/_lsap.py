"""SciPy's ``linear_sum_assignment`` without importing ``scipy.optimize`` (about 0.6 s of CPU): its extension module
``scipy/optimize/_lsap`` loaded directly under its own name (the ordinary import where it cannot be found)."""

from __future__ import annotations

import importlib.machinery
import importlib.util
import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any

_NAME = "scipy.optimize._lsap"
_solver: Callable[..., Any] | None = None


def _load() -> Callable[..., Any]:
    module = sys.modules.get(_NAME)
    if module is None:
        import scipy

        folder = Path(scipy.__file__).parent / "optimize"
        path = next((p for s in importlib.machinery.EXTENSION_SUFFIXES if (p := folder / f"_lsap{s}").is_file()), None)
        spec = importlib.util.spec_from_file_location(_NAME, path) if path is not None else None
        if spec is not None and spec.loader is not None:
            try:
                loaded = importlib.util.module_from_spec(spec)
                spec.loader.exec_module(loaded)
                sys.modules[_NAME] = module = loaded
            except ImportError:
                pass
    found: Callable[..., Any] | None = getattr(module, "linear_sum_assignment", None)
    if found is None:  # another SciPy layout: the ordinary (slower) import
        from scipy.optimize import linear_sum_assignment

        found = linear_sum_assignment
    return found


def solver() -> Callable[..., Any]:
    """scipy's ``linear_sum_assignment`` function itself, loaded on first use."""
    global _solver
    if _solver is None:
        _solver = _load()
    return _solver


def linear_sum_assignment(cost: Any, maximize: bool = False) -> tuple[Any, Any]:
    """``scipy.optimize.linear_sum_assignment(cost, maximize)``: row and column indices (int arrays)
    of a minimum-cost (maximum with ``maximize``) complete assignment of the smaller side."""
    return solver()(cost, maximize)  # type: ignore[no-any-return]
