"""The node under a random mix of valid and invalid datagrams on loopback (10 s here;
benchmarks/node_soak.py runs it for 60 s with the same benchmarks/_soak.py)."""

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))
from _soak import soak  # noqa: E402


def test_node_survives_a_random_mix():
    result = soak(10.0, seed=0)
    c = result.counters
    assert result.alive, "the node stopped answering"
    assert result.consistent(), c  # every datagram read is counted under exactly one outcome
    assert result.final_ok, result.final_team  # the last frame's team state is right
    assert result.sent["invalid"] > 0 and c["rejected_total"] > 0 and c["reports"] > 0 and c["frames"] > 0
    assert c["handler_errors"] == 0 and c["tracker_errors"] == 0
    assert result.max_queued <= 128 and result.max_buckets <= 64  # the configured bounds
    assert c["queue_dropped"] + c["queue_full"] > 0  # the floods hit the queue bounds
    assert not result.rss_peak_mb - result.rss_start_mb > 64, result.summary()
