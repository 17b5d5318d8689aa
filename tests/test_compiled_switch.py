"""The switch of the optional compiled kernels (lookalike._compiled): loaded once on first need, off when they do
not import, when the environment variable is 0 or when forced off; decide_once reads the switch once."""

from __future__ import annotations

import subprocess
import sys
from collections.abc import Callable

import pytest

from lookalike._compiled import KernelSwitch

ENV = "LOOKALIKE_TEST_SWITCH_NUMBA"


def _counting_load(result: object) -> tuple[list[int], Callable[[], object]]:
    calls: list[int] = []

    def load() -> object:
        calls.append(1)
        return result

    return calls, load


def test_loaded_once_and_only_when_needed(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv(ENV, "0")
    calls, load = _counting_load("kernels")
    switch: KernelSwitch[object] = KernelSwitch(ENV, load)
    assert switch.compiled() is None and not calls  # off: nothing loaded
    monkeypatch.delenv(ENV)
    assert switch.compiled() == "kernels" and switch.compiled() == "kernels" and len(calls) == 1
    switch.use_compiled(False)
    assert switch.compiled() is None and switch.kernels() == "kernels"
    switch.use_compiled(True)
    monkeypatch.setenv(ENV, "0")
    assert switch.compiled() == "kernels"  # forced on: the environment is not read
    assert len(calls) == 1


def test_an_import_error_means_no_kernels() -> None:
    def load() -> object:
        raise ImportError("no numba")

    switch: KernelSwitch[object] = KernelSwitch(ENV, load)
    switch.use_compiled(True)
    assert switch.compiled() is None and switch.kernels() is None


def test_decide_once_reads_the_environment_until_use_compiled(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv(ENV, raising=False)
    switch: KernelSwitch[str] = KernelSwitch(ENV, lambda: "kernels", decide_once=True)
    assert switch.compiled() == "kernels"
    monkeypatch.setenv(ENV, "0")
    assert switch.compiled() == "kernels"  # decided
    switch.use_compiled(None)
    assert switch.compiled() is None  # read again
    every_call: KernelSwitch[str] = KernelSwitch(ENV, lambda: "kernels")
    assert every_call.compiled() is None
    monkeypatch.delenv(ENV)
    assert every_call.compiled() == "kernels"


def test_importing_the_switches_does_not_import_numba() -> None:
    code = ("import sys, lookalike, lookalike._compiled, lookalike.trackers.kernels.boxtrack, "
            "lookalike.trackers.kernels.world, lookalike.vision.hog_kernels; print('numba' in sys.modules)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "False"
