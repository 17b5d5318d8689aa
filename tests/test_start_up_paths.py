"""Start-up and I/O fast paths (issue 18) give what the plain ones give."""

from __future__ import annotations

import numpy as np
import pytest

from lookalike.io import MotWriter
from lookalike.io.motchallenge import format_rows


def format_row(row: np.ndarray) -> str:
    """One result row as a line of a MOTChallenge file (boxes to 1/1000 px), newline included: the plain
    formatting :func:`format_rows` must equal."""
    return (f"{int(row[0])},{int(row[1])},{row[2]:.3f},{row[3]:.3f},{row[4]:.3f},"
            f"{row[5]:.3f},{row[6]:g},{row[7]:g},{row[8]:g},{row[9]:g}\n")


def test_lsap_is_scipys_function_with_the_same_results():
    from scipy.optimize import linear_sum_assignment as scipy_lsap

    from lookalike._lsap import linear_sum_assignment

    rng = np.random.default_rng(3)
    for shape in [(1, 1), (3, 5), (6, 4), (20, 20), (0, 3)]:
        cost = rng.integers(0, 4, size=shape).astype(float)  # ties: the same tie-breaking
        for maximize in (False, True):
            ours, theirs = linear_sum_assignment(cost, maximize), scipy_lsap(cost, maximize)
            assert all(np.array_equal(a, b) for a, b in zip(ours, theirs))
    with pytest.raises(ValueError):
        linear_sum_assignment(np.array([[np.nan]]))


def test_builtin_tracker_list_is_complete():
    import importlib
    import pkgutil

    import lookalike.trackers as package
    from lookalike.trackers import registry

    for info in pkgutil.walk_packages(package.__path__, prefix="lookalike.trackers."):
        importlib.import_module(info.name)
    ours = {name for name, cls in registry._REGISTRY.items() if cls.__module__.startswith("lookalike.trackers.")}
    assert ours == set(registry.BUILTIN_TRACKERS)
    assert all(registry._REGISTRY[n].__module__ == m for n, m in registry.BUILTIN_TRACKERS.items())
    assert set(registry.tracker_names()) >= set(registry.BUILTIN_TRACKERS) | {"lstm", "set"}


def test_format_rows_equals_format_row():
    rng = np.random.default_rng(0)
    rows = rng.normal(0, 1e3, (3000, 10))
    rows[:, 0] = rng.integers(1, 10**6, len(rows))
    rows[:, 1] = rng.integers(-5, 10**4, len(rows))
    rows[::7, 6], rows[::11, 7], rows[::13, 8], rows[::17, 2] = np.nan, np.inf, -0.0, -0.0004
    rows[::19, 3], rows[::23, 9], rows[::29, 4] = 1e17, 1e-7, 2.0005
    assert format_rows(rows) == "".join(format_row(r) for r in rows)
    assert format_rows(np.zeros((0, 10))) == ""
    with pytest.raises(ValueError, match="shape"):
        format_rows(np.zeros((2, 6)))


def test_writer_buffers_and_writes_every_row_once(tmp_path):
    rng = np.random.default_rng(1)
    blocks = [rng.normal(0, 100, (k, 10)) for k in rng.integers(0, 900, 30)]
    expected = "".join(format_row(r) for b in blocks for r in b)
    with MotWriter(tmp_path / "out.txt") as writer:
        for block in blocks:
            writer.write_rows(block)
            block[:] = 0  # the caller reusing its array changes nothing written
    assert writer.rows == sum(len(b) for b in blocks)
    assert (tmp_path / "out.txt").read_text() == expected


@pytest.mark.parametrize(("given", "expected"), [(None, "1"), ("2", "2")])
def test_the_program_runs_blas_on_one_thread_unless_told(given, expected):
    import os
    import subprocess
    import sys

    pytest.importorskip("threadpoolctl")
    code = ("import os, sys; sys.argv = ['lookalike']; import lookalike.cli, numpy, threadpoolctl; "
            "pools = [p['num_threads'] for p in threadpoolctl.threadpool_info() if p['internal_api'] == 'openblas']; "
            "print(os.environ.get('OPENBLAS_NUM_THREADS'), pools[0] if pools else 'none')")
    env = {k: v for k, v in os.environ.items() if k != "OPENBLAS_NUM_THREADS"}
    if given is not None:
        env["OPENBLAS_NUM_THREADS"] = given
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, check=True).stdout
    variable, pool = out.split()
    assert variable == expected
    if pool != "none":  # numpy's OpenBLAS read it: the variable was set before numpy was imported
        assert int(pool) <= int(expected)


def test_the_library_leaves_blas_threads_alone():
    import os
    import subprocess
    import sys

    code = "import os, lookalike.cli; print(os.environ.get('OPENBLAS_NUM_THREADS'))"
    env = {k: v for k, v in os.environ.items() if k != "OPENBLAS_NUM_THREADS"}
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, check=True).stdout
    assert out.strip() == "None"


def test_the_trackers_solver_does_not_import_scipy_optimize():
    import subprocess
    import sys

    code = ("import sys, numpy as np; from lookalike.association.solver import assign; "
            "m = assign(np.array([[1.0, 2.0], [1.0, 3.0]])).matches.tolist(); "
            "print(m, 'scipy.optimize' in sys.modules)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.strip() == "[[0, 1], [1, 0]] False"  # a real solve (the pairs overlap), scipy.optimize left alone
