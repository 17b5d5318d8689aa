"""The beacon identifier and per-detection labels."""

from __future__ import annotations

import numpy as np
import pytest

from lookalike.trackers.parts.identity import (
    BeaconIdentifier,
    IdentifierConfig,
    labels_from_tracks,
)
from lookalike.types import Beacons, TrackSnapshot, TrackStatus


def _snap(track_id, agent, det, prob):
    return TrackSnapshot(track_id=track_id, status=TrackStatus.CONFIRMED, agent_id=agent, identity_prob=prob,
                         detection_index=det)


def test_labels_from_tracks():
    tracks = [_snap(1, 0, 2, 0.9), _snap(2, 1, 2, 0.5), _snap(3, None, 0, None), _snap(4, 1, 1, 0.8),
              _snap(5, 0, 0, 0.1)]
    assert labels_from_tracks(4, tracks).tolist() == [-1, 1, 0, -1]
    assert labels_from_tracks(0, []).tolist() == []
    with pytest.raises(ValueError, match="detection_index"):
        labels_from_tracks(1, [_snap(1, 0, 3, 0.5)])


def test_report_age_compensation():
    ident = BeaconIdentifier(IdentifierConfig(n_agents=1))
    # The agent turns at 1 rad/s; reports sent at 0.0 and 0.1 s.
    ident.begin_frame(0.2, Beacons(agent_id=[0, 0], t_sent=[0.0, 0.1], t_received=[0.15, 0.2], heading=[0.0, 0.1]))
    h = ident.agent_headings(np.array([0.05, 0.3, 5.0]))[:, 0]
    np.testing.assert_allclose(h, [0.05, 0.3, 0.1 + 1.0], atol=1e-12)  # interpolated, extrapolated, capped


def test_out_of_order_and_duplicate_reports():
    ident = BeaconIdentifier(IdentifierConfig(n_agents=1))
    ident.begin_frame(1.0, Beacons(agent_id=[0, 0, 0], t_sent=[0.9, 0.5, 0.9], t_received=[1.0] * 3,
                                   heading=[1.0, 0.5, 1.0]))
    np.testing.assert_allclose(ident.agent_headings(np.array([0.7]))[:, 0], [0.75])


def test_assignment_with_hysteresis():
    cfg = IdentifierConfig(n_agents=2, window_frames=5, hysteresis=0.1, max_cost=0.5)
    ident = BeaconIdentifier(cfg)
    reports = Beacons(agent_id=[0, 1], t_sent=[0.0, 0.0], t_received=[0.0, 0.0], heading=[0.0, 1.0])
    ident.begin_frame(0.0, reports)
    ident.observe(1, 0.1)
    ident.observe(2, 0.9)
    first = ident.assign([1, 2])
    assert first[1][0] == 0 and first[2][0] == 1
    # Ambiguous evidence slightly favouring the swap does not flip the identities ...
    for k in range(1, 5):
        ident.begin_frame(k / 30, Beacons.empty())
        ident.observe(1, 0.55)
        ident.observe(2, 0.45)
    second = ident.assign([1, 2])
    assert second[1][0] == 0 and second[2][0] == 1
    # ... clear evidence does.
    for k in range(5, 10):
        ident.begin_frame(k / 30, Beacons.empty())
        ident.observe(1, 1.0)
        ident.observe(2, 0.0)
    third = ident.assign([1, 2])
    assert third[1][0] == 1 and third[2][0] == 0


def test_unheard_agents_and_far_headings_are_not_assigned():
    ident = BeaconIdentifier(IdentifierConfig(n_agents=2, max_cost=0.3))
    ident.begin_frame(0.0, Beacons(agent_id=[0], t_sent=[0.0], t_received=[0.0], heading=[0.0]))
    ident.observe(1, np.pi)  # opposite to the only agent heard from
    assert ident.assign([1]) == {}
    ident.observe(2, 0.0)
    assert ident.assign([1, 2]) == {2: (0, 1.0)}
