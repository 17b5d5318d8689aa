"""Issue 18: the node's labels as a list (no array built) equal ``labels_from_tracks``'s."""

import numpy as np
import pytest

from lookalike.trackers.parts.identity import labels_from_tracks
from lookalike.trackers.parts.identity.labels import label_list
from lookalike.types import Tracks


@pytest.mark.parametrize("seed", range(10))
def test_label_list_equals_labels_from_tracks(seed):
    rng = np.random.default_rng(seed)
    k, n = int(rng.integers(0, 9)), 6
    tracks = Tracks(np.arange(1, k + 1), rng.integers(0, 3, k).astype(np.int8), position=rng.normal(size=(k, 2)),
                    agent_id=rng.integers(-1, 4, k), identity_prob=rng.choice([0.2, 0.5, 0.9, np.nan], k),
                    detection_index=rng.integers(-1, n, k))
    expected = labels_from_tracks(n, tracks).tolist()
    for given in (tracks, list(tracks)):
        out = label_list(n, given)
        assert out == expected
        assert all(type(v) is int for v in out)


def test_label_list_rejects_a_negative_count():
    with pytest.raises(ValueError, match="n_detections"):
        label_list(-1, Tracks(np.zeros(0, dtype=int), np.zeros(0, dtype=np.int8)))
