"""Optional compiled (numba) kernels: their switch (loaded on first use, never by ``import lookalike``; off when
numba does not import, when an environment variable is ``0``, or when forced off) and the compiler's settings."""

from __future__ import annotations

import os
from collections.abc import Callable
from typing import Any, Generic, TypeVar, cast

from lookalike._optional import needs

K = TypeVar("K")
F = TypeVar("F", bound=Callable[..., Any])


def exact_jit() -> Callable[[F], F]:
    """numba's ``njit`` decorator with the settings every kernel module uses: the numpy path's arithmetic kept
    (``fastmath`` off: no fused multiply-adds or reordering; numpy's float error model: division by zero gives
    inf/NaN), compiled code cached on disk, the GIL released, no bounds checks. Imports numba (an
    ``ImportError`` without it): call it only from a kernel module."""
    with needs("numba"):
        import numba  # type: ignore[import-untyped, import-not-found, unused-ignore]

    jit = numba.njit(cache=True, nogil=True, fastmath=False, error_model="numpy", boundscheck=False)
    return cast("Callable[[F], F]", jit)


class KernelSwitch(Generic[K]):
    """Whether a set of compiled kernels ``K`` is in use, and the kernels.

    ``load`` imports the kernels (an ``ImportError``, e.g. numba not installed, or ``None`` returned: not
    available); it runs once, at the first call that needs the kernels. ``env`` names the environment
    variable that switches them off when ``0``. ``decide_once``: :meth:`compiled` reads the forcing and the
    environment once, after which a call costs an attribute lookup (:meth:`use_compiled` makes it read them
    again); otherwise at every call."""

    def __init__(self, env: str, load: Callable[[], K | None], *, decide_once: bool = False) -> None:
        self.env = env
        self._load = load
        self._decide_once = decide_once
        self._forced: bool | None = None
        self._loaded = False
        self._kernels: K | None = None
        self._decided = False
        self._active: K | None = None

    def use_compiled(self, flag: bool | None) -> None:
        """Force the compiled kernels on (``True``, if they load) or off (``False``); ``None``: the default
        (on when they load and the environment variable is not ``0``)."""
        self._forced = None if flag is None else bool(flag)
        self._decided = False
        self._active = None

    def compiled(self) -> K | None:
        """The kernels, or ``None`` when they are off or do not load."""
        if self._decided:
            return self._active
        forced = self._forced
        if forced is False or (forced is None and os.environ.get(self.env, "1") == "0"):
            active = None
        else:
            active = self.kernels()
        if self._decide_once:
            self._active, self._decided = active, True
        return active

    def kernels(self) -> K | None:
        """The kernels whatever the switch says (loaded on first use), ``None`` when they do not load."""
        if not self._loaded:
            try:
                self._kernels = self._load()
            except ImportError:
                self._kernels = None
            self._loaded = True
        return self._kernels
