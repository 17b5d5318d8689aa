"""Independent jobs (picklable top-level callables) run serially, in local processes, or as Ray tasks, with identical
results."""

from __future__ import annotations

import multiprocessing
from collections.abc import Callable, Iterator, Sequence
from concurrent.futures import Future, ProcessPoolExecutor
from contextlib import contextmanager
from typing import Any

from lookalike._optional import needs

BACKENDS = ("local", "ray")


class Pending:
    """A submitted job; :meth:`result` blocks until it is done."""

    def __init__(self, get: Callable[[], Any]) -> None:
        self._get = get

    def result(self) -> Any:
        return self._get()


class JobPool:
    """``submit(fn, *args)`` and ``map(fn, items)`` over ``workers`` processes (1: in this process, when the result is
    asked for) or a Ray cluster (at ``address``, or a local ``ray.init()``); a context manager."""

    def __init__(self, workers: int = 1, backend: str = "local", address: str | None = None) -> None:
        if backend not in BACKENDS:
            raise ValueError(f"backend: expected one of {BACKENDS}, got {backend!r}")
        if workers < 1:
            raise ValueError(f"workers must be >= 1, got {workers}")
        self.workers, self.backend = workers, backend
        self._pool: ProcessPoolExecutor | None = None
        self._ray = init_ray(address, workers) if backend == "ray" else None
        self._remote: dict[Callable, Any] = {}

    def submit(self, fn: Callable[..., Any], *args: Any) -> Pending:
        if self._ray is not None:
            if fn not in self._remote:
                self._remote[fn] = self._ray.remote(fn)
            ref = self._remote[fn].remote(*args)
            ray = self._ray
            return Pending(lambda: ray.get(ref))
        if self.workers > 1:
            if self._pool is None:
                # spawned, not forked: the parent may hold CUDA or Ray state that must not be copied
                self._pool = ProcessPoolExecutor(self.workers, mp_context=multiprocessing.get_context("spawn"))
            future: Future = self._pool.submit(fn, *args)
            return Pending(future.result)
        return Pending(lambda: fn(*args))

    def share(self, obj: Any) -> Any:
        """``obj`` as an argument for many jobs: put once in Ray's object store, or ``obj`` unchanged locally."""
        return self._ray.put(obj) if self._ray is not None else obj

    def map(self, fn: Callable[[Any], Any], items: Sequence[Any]) -> list[Any]:
        """``[fn(x) for x in items]``, in order."""
        return [p.result() for p in [self.submit(fn, x) for x in items]]

    def close(self) -> None:
        if self._pool is not None:
            self._pool.shutdown(cancel_futures=True)
            self._pool = None

    def __enter__(self) -> JobPool:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


def init_ray(address: str | None, workers: int) -> Any:
    """The ``ray`` module, initialised on ``address`` or as a local instance (``workers`` CPUs)."""
    with needs("ray"):
        import ray
    if not ray.is_initialized():
        if address:
            ray.init(address=address, ignore_reinit_error=True, log_to_driver=False)
        else:
            ray.init(num_cpus=workers if workers > 1 else None, ignore_reinit_error=True,
                     include_dashboard=False, log_to_driver=False)
    return ray


@contextmanager
def one_blas_thread() -> Iterator[None]:
    """BLAS and LAPACK on the calling thread only inside the block (threadpoolctl, when installed): faster for the
    small matrices of the heading SVM and the node's per-frame work than a pool's hand-offs."""
    try:
        from threadpoolctl import threadpool_limits
    except ImportError:  # pragma: no cover (scikit-learn, a core dependency, requires it)
        yield
        return
    with threadpool_limits(limits=1, user_api="blas"):
        yield
