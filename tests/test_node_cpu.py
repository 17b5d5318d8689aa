"""Issue 18: the node reports its CPU time per frame beside its latency; kalman_ha runs on numpy < 2."""

import numpy as np
import pytest

from lookalike.node.counters import NodeCounters
from lookalike.trackers.parts import world_tracker as kalman_ha


def test_counters_report_cpu_time_beside_latency():
    counters = NodeCounters()
    assert "cpu_ms" not in counters.snapshot()
    counters.latency_s.extend([0.002, 0.004])
    counters.cpu_s.extend([0.001, 0.003])
    snap = counters.snapshot()
    assert snap["latency_ms"]["median"] == pytest.approx(3.0)
    assert snap["cpu_ms"]["median"] == pytest.approx(2.0) and snap["cpu_ms"]["frames"] == 2


def test_bit_count_without_numpy_2_equals_bitwise_count(monkeypatch):
    bits = np.random.default_rng(0).integers(0, 2**30, 500)
    expected = np.array([bin(int(b)).count("1") for b in bits])
    np.testing.assert_array_equal(kalman_ha.bit_count(bits), expected)
    monkeypatch.delattr(np, "bitwise_count", raising=False)
    np.testing.assert_array_equal(kalman_ha.bit_count(bits), expected)
    assert kalman_ha.bit_count(np.zeros(0, dtype=np.int64)).shape == (0,)
