import numpy as np
import pytest

from lookalike.learn.sim_data import arrays_to_training
from lookalike.sim import preset, simulate_robots
from lookalike.trackers.lstm.encoding import EncodingSpec
from tests.learn_oracle import frames_to_arrays


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


def test_identity_swap_moves_reports_and_targets_together():
    from lookalike.learn.sim_data import latest_reports, swap_identities

    arrays = simulate_robots(preset("m5n3"), 600, seed=5).arrays
    swapped = swap_identities(arrays, 0, 1, 5.0, 10.0)
    h0, _ = latest_reports(arrays, 3)
    h1, _ = latest_reports(swapped, 3)
    k = int(7.5 * 30)  # well inside the swap: reports and labels of 0 and 1 exchanged, robot 2 untouched
    np.testing.assert_array_equal(h1[k], h0[k][[1, 0, 2]])
    before, inside = arrays.det_label[k], swapped.det_label[k]
    np.testing.assert_array_equal(inside, np.select([before == 0, before == 1], [1, 0], before))
    for k in (int(2 * 30), int(13 * 30)):  # before the swap and after its reports are superseded
        np.testing.assert_array_equal(swapped.det_label[k], arrays.det_label[k])
        np.testing.assert_array_equal(h1[k], h0[k])


def test_silence_agent_drops_one_agents_reports_in_the_window_only():
    from lookalike.learn.sim_data import latest_reports, silence_agent

    arrays = simulate_robots(preset("m5n3"), 300, seed=5).arrays
    quiet = silence_agent(arrays, 1, 3.0, 6.0)
    r, q = arrays.reports, quiet.reports
    dropped = (r.agent_id == 1) & (r.t_sent >= 3.0) & (r.t_sent < 6.0)
    assert dropped.any() and len(q.agent_id) == len(r.agent_id) - dropped.sum()
    assert not ((q.agent_id == 1) & (q.t_sent >= 3.0) & (q.t_sent < 6.0)).any()
    for k in range(len(arrays)):  # every frame still carries the same reports, less the dropped ones
        rows = slice(r.frame_offsets[k], r.frame_offsets[k + 1])
        np.testing.assert_array_equal(q.t_sent[q.frame_offsets[k]:q.frame_offsets[k + 1]],
                                      r.t_sent[rows][~dropped[rows]])
    h0, s0 = latest_reports(arrays, 3)
    h1, s1 = latest_reports(quiet, 3)
    k = int(5.5 * 30)  # inside the silence: agent 1's newest report is older, the others' unchanged
    assert s1[k, 1] < 3.0 <= s0[k, 1]
    np.testing.assert_array_equal(h1[k][[0, 2]], h0[k][[0, 2]])
    np.testing.assert_array_equal(quiet.det_label, arrays.det_label)


def test_sim_sampler_is_picklable_and_swaps_only_when_asked():
    import pickle

    from lookalike.learn.sim_data import SimSampler

    plain, always = SimSampler(preset("m3n2")), SimSampler(preset("m3n2"), swap_prob=1.0)
    x0, y0 = pickle.loads(pickle.dumps(plain))(3, 450, None)
    x1, y1 = always(3, 450, None)
    assert x0.shape == x1.shape and not np.array_equal(y0, y1)
    np.testing.assert_array_equal(always(3, 450, None)[1], y1)  # drawn from the seed
    with pytest.raises(ValueError, match="swap_prob"):
        SimSampler(preset("m3n2"), swap_prob=1.5)
