"""Fingerprints of the set identifier's outputs (and lstm's, which shares trackers/parts/agents.py), to show that a
speed-up changes nothing: one sha256 per case over the node's team-state datagrams, the labels and probabilities, or
the snapshots (ids, status, heading, agent, probability, detection, position bytes), frame by frame.

Cases: teams m2n1 .. m12n10 through the node (TeamIdentifier, JSON decode/encode), lossy networks, report-id swaps that
fire report jumps, report and visual exchanges and undo, the lowpass localiser, n_slots, every mechanism off, lstm.

    PYTHONPATH=/tmp/old/src .venv/bin/python research/set/identical_outputs.py /tmp/before.json   # (an older tree)
    .venv/bin/python research/set/identical_outputs.py /tmp/after.json && cmp /tmp/before.json /tmp/after.json
"""

from __future__ import annotations

import dataclasses
import hashlib
import json
import sys
from collections.abc import Callable
from typing import Any

import numpy as np

from lookalike.node import IdentifierConfig, TeamIdentifier, decode, encode
from lookalike.node.teamsim import camera_messages, robot_reports, team_sequence
from lookalike.trackers import make_tracker
from lookalike.types import Beacons

OFF = dict(stale_s=None, fp_prior_ref=None, report_jump=None, exchange_llr=None, visual_exchange=None,
           undo_factor=None)


def node_case(name: str, seq: Any, **params: Any) -> list[bytes]:
    """Each frame's team-state datagram and the tracker's labels and probabilities, through the node's core."""
    n = seq.config.n_agents
    ident = TeamIdentifier(make_tracker(name, n_agents=n, **params), IdentifierConfig(n_robots=n))
    reports = sorted((it for j in range(n) for it in robot_reports(seq, j)), key=lambda it: it[0])
    out, i = [], 0
    for data in [encode(m) for m in camera_messages(seq)]:
        msg = decode(data)
        while i < len(reports) and reports[i][0] <= msg.time:  # type: ignore[union-attr]
            ident.add_report(reports[i][1])
            i += 1
        _, team = ident.add_frame(msg)  # type: ignore[arg-type]
        assert team is not None
        out.append(encode(team))
        t = ident.tracker
        out.append(np.asarray(t.last_labels).tobytes() + np.asarray(t.last_probabilities).tobytes())
        ident.prepare()
    return out


def direct_case(name: str, frames: Any, n: int, **params: Any) -> list[bytes]:
    """Each frame's labels, probabilities and snapshots of the tracker fed ``frames`` directly."""
    t = make_tracker(name, n_agents=n, **params)
    out = []
    for f in frames:
        snaps = t.update(f)
        out.append(np.asarray(t.last_labels).tobytes() + np.asarray(t.last_probabilities).tobytes())
        for s in snaps:
            fields = (s.track_id, s.status, s.heading, s.agent_id, s.identity_prob, s.detection_index)
            out.append(repr(fields).encode() + np.asarray(s.position).tobytes())
        out.append(b"|")
    return out


def swapped(seq: Any, swaps: list[tuple[float, dict[int, int]]]) -> list[Any]:
    """The frames with report ids exchanged from each ``(send time s, {agent: agent})`` on, one after the other."""
    frames = []
    for f in seq.frames():
        b = f.beacons
        ids = b.agent_id.copy()
        for t0, mapping in swaps:
            ids = np.array([mapping.get(int(i), int(i)) if ts >= t0 else int(i) for i, ts in zip(ids, b.t_sent)],
                           dtype=int)
        beacons = Beacons(agent_id=ids, t_sent=b.t_sent, t_received=b.t_received, heading=b.heading)
        frames.append(dataclasses.replace(f, beacons=beacons))
    return frames


def cases() -> list[tuple[str, Callable[[], list[bytes]]]]:
    out: list[tuple[str, Callable[[], list[bytes]]]] = []
    lossy = dict(loss=0.3, delay_s=0.15, jitter_s=0.1)
    for setup, n in [("m3n2", 2), ("m5n3", 3), ("m7n4", 4), ("m10n7", 7), ("m12n10", 10)]:
        twice = [(4.0, {0: 1, 1: 0}), (9.0, {n - 1: n - 2, n - 2: n - 1}), (11.0, {0: 1, 1: 0})]
        undo = [(3.0, {0: 1, 1: 0}), (3.5, {0: 1, 1: 0}), (6.0, {0: 1, 1: 0})]
        runs = (("swap", 11, twice, {}), ("swap-lossy", 12, twice, dict(lossy, delay_s=0.2)),
                ("swap-undo", 13, undo, {}))
        for label, seed, swaps, network in runs:
            out.append((f"{label}-{setup}", lambda s=setup, d=seed, w=swaps, k=network, n=n: direct_case(
                "set", swapped(team_sequence(s, d, 16.0, **k), w), n)))
    for setup, n in [("m3n2", 2), ("m5n3", 3), ("m10n7", 7), ("m7n4", 4), ("m12n10", 10), ("m2n1", 1)]:
        for seed in (0, 1):
            out.append((f"node-{setup}-{seed}", lambda s=setup, d=seed: node_case("set", team_sequence(s, d, 12.0))))
        out.append((f"lossy-{setup}", lambda s=setup: node_case("set", team_sequence(s, 5, 12.0, **lossy))))
        out.append((f"direct-{setup}", lambda s=setup, n=n: direct_case(
            "set", team_sequence(s, 3, 12.0, loss=0.1).frames(), n)))
    m10n7 = lambda: team_sequence("m10n7", 4, 12.0).frames()  # noqa: E731
    out += [("lowpass-m10n7", lambda: direct_case("set", m10n7(), 7, localiser="lowpass")),
            ("slots-m10n7", lambda: direct_case("set", m10n7(), 7, n_slots=4)),
            ("off-m5n3", lambda: direct_case("set", team_sequence("m5n3", 4, 12.0).frames(), 3, **OFF)),
            ("lossy-heavy-m5n3", lambda: node_case("set", team_sequence("m5n3", 8, 20.0, loss=0.6, delay_s=0.5,
                                                                        jitter_s=0.4))),
            ("lstm-m3n2", lambda: direct_case("lstm", team_sequence("m3n2", 2, 12.0, loss=0.2).frames(), 2,
                                              n_slots=3)),
            ("lstm-m10n7", lambda: direct_case("lstm", team_sequence("m10n7", 2, 12.0).frames(), 7, n_slots=10))]
    return out


def main() -> None:
    result = {}
    for key, run in cases():
        chunks = run()
        result[key] = hashlib.sha256(b"\0".join(chunks)).hexdigest()
        print(key, result[key][:16], len(chunks), flush=True)
    with open(sys.argv[1], "w") as out:
        json.dump(result, out, indent=1, sort_keys=True)


if __name__ == "__main__":
    main()
