"""Issue 18: world_kernels' wrapper-free calls give what the numpy functions they stand in for give."""

import numpy as np
import pytest

from lookalike.trackers.kernels.world import einsum, filled


@pytest.mark.parametrize(("shape", "value", "dtype"), [(0, np.nan, float), (5, -1, int), ((3, 4), np.inf, float)])
def test_filled_equals_np_full(shape, value, dtype):
    out, expected = filled(shape, value, dtype), np.full(shape, value, dtype=dtype)
    assert out.dtype == expected.dtype and out.shape == expected.shape
    np.testing.assert_array_equal(out, expected)


def test_einsum_bits_equal_np_einsum():
    rng = np.random.default_rng(0)
    K, v = rng.normal(size=(9, 6, 2)), rng.normal(size=(9, 2)) * 1e3
    assert einsum("kij,kj->ki", K, v).tobytes() == np.einsum("kij,kj->ki", K, v).tobytes()
