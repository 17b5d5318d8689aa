"""Optional compiled (numba) kernels: their switch (off when numba does not import, when an environment variable is
``0``, or when forced off) and the compiler's settings. numba caches compiled code on disk, so a machine compiles each
kernel once (one line on stderr says so)."""

from __future__ import annotations

import atexit
import contextlib
import os
import sys
import time
from collections.abc import Callable
from types import ModuleType
from typing import Any, Generic, TypeVar, cast

from lookalike._optional import needs

K = TypeVar("K")
T = TypeVar("T")
F = TypeVar("F", bound=Callable[..., Any])


def exact_jit() -> Callable[[F], F]:
    """numba's ``njit`` with the numpy path's arithmetic (no ``fastmath``, numpy's float error model), an on-disk
    cache, the GIL released and no bounds checks. Imports numba (an ``ImportError`` without it)."""
    with needs("numba"):
        import numba  # type: ignore[import-untyped, import-not-found, unused-ignore]

    _announce_compiles(numba)
    jit = numba.njit(cache=True, nogil=True, fastmath=False, error_model="numpy", boundscheck=False)
    return cast("Callable[[F], F]", jit)


COMPILE_SECONDS = {"lookalike.trackers.kernels.boxtrack_numba": 6, "lookalike.trackers.kernels.world_numba": 10,
                   "lookalike.vision.hog_numba": 5}
"""About how long each kernel module takes to compile on a laptop core (s), for the message."""

compile_aside = False
"""Set by the ``lookalike`` program: kernels with a ``warm`` function that are not cached yet are compiled in a
separate process when this run (which takes the numpy path) ends."""

_announced = False


def _say(message: str) -> None:
    print(message, file=sys.stderr, flush=True)


def _announce_compiles(numba: Any) -> None:
    """Print one line on stderr at the first compile of a lookalike kernel in this process."""
    global _announced
    if _announced:
        return
    _announced = True
    with needs("numba"):
        from numba.core import event  # type: ignore[import-untyped, import-not-found, unused-ignore]

    class _Once(event.Listener):  # type: ignore[misc, name-defined, unused-ignore]
        said = False

        def on_start(self, ev: Any) -> None:
            module = str(getattr(getattr((ev.data or {}).get("dispatcher"), "py_func", None), "__module__", ""))
            if not self.said and module.startswith("lookalike."):
                self.said = True
                _say(f"compiling the fast kernels once (about {COMPILE_SECONDS.get(module, 10)} s); later runs load "
                     "them from numba's cache…")

        def on_end(self, ev: Any) -> None:
            pass

    event.register("numba:compile", _Once())


def kernels_cached(module: ModuleType) -> bool:
    """Whether every numba kernel defined in ``module`` has compiled code in numba's cache for the current source."""
    found = False
    for value in vars(module).values():
        cache = getattr(value, "_cache", None)
        if getattr(getattr(value, "py_func", None), "__module__", None) != module.__name__ or cache is None:
            continue
        found = True
        index = getattr(getattr(cache, "_cache_file", None), "_load_index", None)
        try:
            if index is None or not index():
                return False
        except OSError:
            return False
    return found


def _compile_elsewhere(warm: str, module: ModuleType) -> None:
    """Start ``warm`` ("module:function", which compiles the kernels by running them) in a detached process when
    this one exits, unless one was started less than two minutes ago (a stamp file beside the cache)."""
    stamp = next((os.path.join(v._cache._cache_path, f".{module.__name__}.compiling") for v in vars(module).values()
                  if getattr(getattr(v, "_cache", None), "_cache_path", None)), None)
    if stamp is not None:
        with contextlib.suppress(OSError):
            if time.time() - os.path.getmtime(stamp) < 120:
                return
        with contextlib.suppress(OSError):
            os.makedirs(os.path.dirname(stamp), exist_ok=True)
            with open(stamp, "w") as f:
                f.write(str(os.getpid()))
    name, function = warm.split(":")
    code = f"import os; os.nice(10); from {name} import {function}; {function}()"
    seconds = COMPILE_SECONDS.get(module.__name__, 10)
    _say(f"the fast kernels are not compiled yet: this run takes the numpy path (the same results) and they compile "
         f"once, in the background when it ends (about {seconds} s)…")

    def start() -> None:  # after the run, so that it does not share the CPU with the compiler
        import subprocess

        subprocess.Popen([sys.executable, "-c", code], stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL,
                         stderr=subprocess.DEVNULL, start_new_session=True)

    atexit.register(start)


class KernelSwitch(Generic[K]):
    """Whether a set of compiled kernels ``K`` is in use, and the kernels.

    ``load`` imports them once, when first needed (an ``ImportError`` or ``None``: not available); ``env``: the
    environment variable that switches them off when ``0``; ``decide_once``: :meth:`compiled` reads the forcing and
    the environment once (until :meth:`use_compiled`); ``warm``: "module:function" compiling them, for
    :data:`compile_aside`; ``load_after_s``: :meth:`due` waits until the numpy path has taken this long in the
    process (:meth:`timed`), about what importing numba and loading the kernels costs (None: no wait)."""

    def __init__(self, env: str, load: Callable[[], K | None], *, decide_once: bool = False,
                 warm: str | None = None, load_after_s: float | None = None) -> None:
        self.env = env
        self._load = load
        self._decide_once = decide_once
        self._warm = warm
        self._load_after_s = load_after_s
        self._spent = 0.0
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

    def timed(self, numpy_path: Callable[..., T], *args: Any) -> T:
        """``numpy_path(*args)``, its time counted towards :meth:`due` (the numpy path while not decided), at most
        0.05 s a call: a one-off import inside a call (such as scipy's solver) is not work the kernels would save."""
        start = time.perf_counter()
        try:
            return numpy_path(*args)
        finally:
            self._spent += min(time.perf_counter() - start, 0.05)

    def due(self) -> bool:
        """Whether to ask :meth:`compiled` now: it costs nothing (forced either way, switched off, already loaded)
        or loading the kernels pays (the numpy path has taken ``load_after_s``). Both paths give the same
        numbers, so this decides only speed."""
        return (self._forced is not None or self._loaded or os.environ.get(self.env, "1") == "0"
                or self._load_after_s is None or self._spent >= self._load_after_s)

    def compiled(self) -> K | None:
        """The kernels, or ``None`` when they are off or do not load."""
        if self._decided:
            return self._active
        forced = self._forced
        if forced is False or (forced is None and os.environ.get(self.env, "1") == "0"):
            active = None
        else:
            active = self.kernels()
            if (forced is None and compile_aside and self._warm is not None and isinstance(active, ModuleType)
                    and not kernels_cached(active)):
                _compile_elsewhere(self._warm, active)
                active = None
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
