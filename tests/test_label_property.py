"""Issue 19: arbitrary request bodies to the label save endpoints never give a 500 or a traceback,
and never leave a partial label file (property-based, hypothesis)."""

from __future__ import annotations

import http.client
import json
import threading

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from lookalike.io.robot_sequences import write_robot_sequence
from lookalike.sim import preset, simulate_robots
from lookalike.viz.label import make_server, open_label_app
from lookalike.viz.label.store import FORMAT, UNSET


@pytest.fixture(scope="module")
def served(tmp_path_factory):
    folder = tmp_path_factory.mktemp("label-prop")
    path = write_robot_sequence(folder / "m3n2-000005.jsonl", simulate_robots(preset("m3n2"), 12, 5))
    app = open_label_app(path)
    server = make_server(app, port=0, body_timeout_s=2.0)
    thread = threading.Thread(target=server.serve_forever, daemon=True)
    thread.start()
    yield server, app
    server.shutdown()
    server.server_close()
    thread.join(5)


def _post(server, path: str, body: bytes) -> tuple[int, bytes]:
    conn = http.client.HTTPConnection("127.0.0.1", server.server_address[1], timeout=10)
    conn.request("POST", path, body=body, headers={"Content-Type": "application/json"})
    r = conn.getresponse()
    data = r.read()
    conn.close()
    return r.status, data


def _check_label_file(app) -> None:
    doc = json.loads(app.store.path.read_text())  # complete JSON, never a partial write
    assert doc["format"] == FORMAT
    assert [len(row) for row in doc["labels"]] == app.store.counts
    assert all(UNSET <= v < app.store.n_agents for row in doc["labels"] for v in row)
    assert not [p for p in app.folder.iterdir() if p.name.endswith(".tmp")]


json_values = st.recursive(
    st.none() | st.booleans() | st.integers(min_value=-(2**70), max_value=2**70) | st.floats() | st.text(max_size=8),
    lambda children: st.lists(children, max_size=3) | st.dictionaries(st.text(max_size=6), children, max_size=3),
    max_leaves=8,
)
label_bodies = st.fixed_dictionaries(
    {}, optional={"frame": json_values | st.integers(-2, 14), "detection": json_values | st.integers(-1, 5),
                  "label": json_values | st.integers(-3, 3), "extra": json_values},
)


def _encode(value) -> bytes:
    return json.dumps(value, allow_nan=True).encode()


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(body=st.one_of(st.binary(max_size=200), label_bodies.map(_encode), json_values.map(_encode)))
def test_label_saves_never_fail_with_500(served, body):
    server, app = served
    status, data = _post(server, "/api/label", body)
    assert status in (200, 400), (body, status, data)
    reply = json.loads(data)
    assert ("ok" in reply) if status == 200 else ("error" in reply and "Traceback" not in reply["error"])
    _check_label_file(app)


@settings(max_examples=15, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(path=st.sampled_from(["/api/export", "/api/benchmark/start", "/api/benchmark/finish"]),
       body=st.one_of(st.binary(max_size=100), json_values.map(_encode)))
def test_other_posts_never_fail_with_500(served, path, body):
    server, app = served
    status, data = _post(server, path, body)
    assert status < 500, (path, body, status, data)
    _check_label_file(app)


@settings(max_examples=150, deadline=None)
@given(frame=json_values, detection=json_values, label=json_values)
def test_store_set_label_raises_only_value_error(tmp_path_factory, frame, detection, label):
    from lookalike.viz.label.store import LabelStore

    folder = tmp_path_factory.mktemp("store")
    store = LabelStore(folder / "x.labels.json", "x.jsonl", [2, 0, 3], 2)
    try:
        store.set_label(frame, detection, label)
    except ValueError:
        pass
    doc = json.loads(store.path.read_text())
    assert [len(r) for r in doc["labels"]] == [2, 0, 3]
