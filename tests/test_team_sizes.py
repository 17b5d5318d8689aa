"""Every command that takes a robot team runs with a team size no preset or shipped LSTM has (issue 49): simulate,
bench ident/recovery/pixels, record-pixels, train, label, track --bag and render on tiny inputs; the LSTM refuses
such a team in one line that names the set identifier. (serve, robot-sim and camera-sim with four robots:
tests/test_node_cli.py.)"""

import json

import pytest
from typer.testing import CliRunner

from lookalike.cli import app

runner = CliRunner()
TEAM = "m7n4"  # 4 robots, at most 7 detections a frame


def _ok(args: list[str]) -> str:
    r = runner.invoke(app, args)
    assert r.exit_code == 0, r.output
    return r.output


def _one_line_error(args: list[str], *needles: str) -> None:
    r = runner.invoke(app, args)
    errors = [line for line in r.output.splitlines() if line.startswith("error")]
    assert r.exit_code != 0 and len(errors) == 1, r.output
    assert all(n in errors[0] for n in needles), r.output


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    """A 12-frame m7n4 run as .jsonl and as a rosbag2 folder with its rendered frames."""
    pytest.importorskip("rosbags", reason="bags need the 'ros' extra")
    pytest.importorskip("cv2", reason="the images need the 'vision' extra")
    folder = tmp_path_factory.mktemp("team")
    out = _ok(["simulate", "--preset", TEAM, "--frames", "12", "--seed", "3", "--bag", "--images", "-o", str(folder)])
    assert "12 frames" in out
    return folder / f"{TEAM}-000003.jsonl", folder / f"{TEAM}-000003"


def test_simulate_writes_the_team(run):
    from lookalike.io.robot_sequences import read_robot_sequence

    config = read_robot_sequence(run[0]).config
    assert (config.n_agents, config.max_detections, config.sensor.fp_per_frame) == (4, 7, 0.9)
    _one_line_error(["simulate", "--preset", "m7x4", "-o", str(run[0].parent / "x")], "--preset", "mMnN")


def test_bench_ident_scores_set_and_leaves_the_lstm_untrained(tmp_path):
    out = tmp_path / "rows.json"
    _ok(["bench", "ident", "--setups", f"{TEAM},n12m15", "--trackers", "set,jpda,lstm", "--sequences", "1",
         "--frames", "20", "--json", str(out)])
    rows = {(r["dataset"], r["tracker"]): r["metrics"] for r in json.loads(out.read_text())["tables"]["ident"]}
    assert 0 <= rows[(TEAM, "set")]["success_rate"] <= 1 and 0 <= rows[("n12m15", "jpda")]["success_rate"] <= 1
    assert rows[(TEAM, "lstm")].get("success_rate") is None


def test_bench_recovery_and_the_lstms_one_line_error():
    assert "Recovery" in _ok(["bench", "recovery", "--setups", TEAM, "--trackers", "set", "--sequences", "1",
                              "--frames", "300", "--swap-at-s", "2", "--swap-s", "4"])
    out = _ok(["bench", "shuffle", "--setups", TEAM, "--sequences", "1", "--frames", "60"])  # default: jpda, lstm
    assert "lstm left out" in out and "jpda" in out
    _one_line_error(["bench", "recovery", "--setups", TEAM, "--trackers", "lstm", "--sequences", "1",
                     "--frames", "300", "--swap-at-s", "2", "--swap-s", "4"], "M=7, N=4", "set identifier")


def test_bench_pixels_and_record_pixels(tmp_path):
    pytest.importorskip("cv2", reason="the pixel pipeline needs the 'vision' extra")
    assert "M=7, N=4" in _ok(["bench", "pixels", "--setups", TEAM, "--trackers", "set", "--sequences", "1",
                              "--frames", "4"])
    assert "lstm left out" in _ok(["bench", "pixels", "--setups", TEAM, "--sequences", "1", "--frames", "2"])
    _ok(["record-pixels", "--preset", TEAM, "--sequences", "1", "--frames", "4", "-o", str(tmp_path)])
    assert len(list(tmp_path.glob(f"*{TEAM}*.labelled.jsonl"))) == 1


def test_train_an_lstm_for_the_team(tmp_path):
    pytest.importorskip("torch", reason="training needs torch (the 'train' extra)")
    _ok(["train", "--preset", TEAM, "--steps", "1", "--sequence-length", "150", "--batch-size", "2",
         "--hidden", "8", "--layers", "1", "--validate-every", "1", "-o", str(tmp_path)])
    meta = json.loads((tmp_path / "model.json").read_text())
    assert (meta["info"]["config"]["n_agents"], meta["info"]["config"]["n_slots"]) == (4, 7)


def test_label_starts_from_set_and_refuses_the_lstm(run, tmp_path):
    seq = tmp_path / "run.jsonl"
    seq.write_bytes(run[0].read_bytes())
    _one_line_error(["label", str(seq), "--tracks", "lstm", "--export"], "M=7, N=4", "set identifier")
    assert "rows" in _ok(["label", str(seq), "--tracks", "set", "--export"])


def test_track_bag_defaults_to_set_and_render_draws_it(run, tmp_path):
    tracks = tmp_path / "tracks.txt"
    _ok(["track", "--bag", str(run[1]), "--camera-topic", "/camera/image_raw", "-o", str(tracks)])
    ids = {int(line.split(",")[1]) for line in tracks.read_text().splitlines()}
    assert ids and ids <= {1, 2, 3, 4}
    _ok(["render", "--tracks", str(tracks), "--birdseye", "-o", str(tmp_path / "above.mp4")])
    assert (tmp_path / "above.mp4").stat().st_size > 0


def test_serve_refuses_an_lstm_it_has_no_weights_for(tmp_path):
    _one_line_error(["serve", "--tracker", "lstm", "--robots", "4", "--duration", "0.1"], "N=4", "set identifier")
    port_file = tmp_path / "port"  # 7 robots: the shipped M=10, N=7 weights, without --set n_slots=10
    _ok(["serve", "--tracker", "lstm", "--robots", "7", "--duration", "0.1", "--listen", "127.0.0.1:0",
         "--port-file", str(port_file)])
    assert port_file.read_text().startswith("127.0.0.1:")
