import pytest

from lookalike.parallel import JobPool


def square(x: int) -> int:
    return x * x


@pytest.mark.parametrize("workers", [1, 2])
def test_local_pool_maps_in_order(workers):
    with JobPool(workers) as pool:
        assert pool.map(square, range(7)) == [x * x for x in range(7)]
        assert pool.submit(square, 9).result() == 81


def test_bad_pool_settings_are_refused():
    with pytest.raises(ValueError, match="backend"):
        JobPool(backend="dask")
    with pytest.raises(ValueError, match="workers"):
        JobPool(0)


def test_ray_pool_gives_the_same_results():
    ray = pytest.importorskip("ray", reason="the Ray backend needs the 'ray' extra")
    try:
        with JobPool(2, backend="ray") as pool:
            assert pool.map(square, range(5)) == [0, 1, 4, 9, 16]
    finally:
        ray.shutdown()
