import numpy as np
import pytest

from lookalike.learn.data import frames_to_arrays
from lookalike.learn.encoding import EncodingSpec
from lookalike.learn.sim_data import arrays_to_training
from lookalike.sim import preset, simulate_robots


@pytest.mark.parametrize("name, relative", [("m3n2", False), ("m10n7", False), ("m5n3", True), ("m10n7", True)])
def test_vectorised_encoding_equals_frame_by_frame(name, relative):
    config = preset(name)
    seq = simulate_robots(config, 300, seed=4)
    spec = EncodingSpec(config.n_agents, config.max_detections, relative_headings=relative)
    x_fast, y_fast = arrays_to_training(spec, seq.arrays)
    x_slow, y_slow = frames_to_arrays(spec, list(seq.frames()))
    np.testing.assert_allclose(x_fast, x_slow, atol=1e-12)
    np.testing.assert_array_equal(y_fast, y_slow)


def test_shuffled_slots_keep_inputs_and_targets_together():
    config = preset("m5n3")
    seq = simulate_robots(config, 200, seed=1)
    spec = EncodingSpec(config.n_agents, config.max_detections)
    x0, y0 = arrays_to_training(spec, seq.arrays)
    x1, y1 = arrays_to_training(spec, seq.arrays, np.random.default_rng(0))
    n_agent = 3 * spec.n_agents
    np.testing.assert_array_equal(x0[:, :n_agent], x1[:, :n_agent])
    s0 = x0[:, n_agent:].reshape(len(x0), spec.n_slots, 5)
    s1 = x1[:, n_agent:].reshape(len(x1), spec.n_slots, 5)
    for t in range(len(x0)):
        a = sorted(zip(map(tuple, s0[t].round(12)), y0[t]))
        b = sorted(zip(map(tuple, s1[t].round(12)), y1[t]))
        assert a == b
    assert not np.array_equal(y0, y1)  # some frame was really shuffled
