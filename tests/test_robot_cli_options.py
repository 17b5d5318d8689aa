"""The robot commands name the option a bad value came from, before any work (a negative ``--seed``: numpy's seeds
are non-negative)."""

from __future__ import annotations

import os

import pytest
from typer.testing import CliRunner

from lookalike.cli import app


@pytest.mark.parametrize("args", [
    ["simulate", "--preset", "m3n2", "--frames", "2"],
    ["simulate", "--arena", "2", "--frames", "2"],
    ["render-robots", "missing.jsonl"],
    ["record-pixels", "--preset", "m3n2", "--sequences", "1", "--frames", "1"],
    ["robot-sim", "--robot", "1", "--duration", "1"],
    ["camera-sim", "--duration", "1"],
    ["train-detector"],
    ["train-heading"],
])
def test_negative_seed_is_refused_by_name(tmp_path, args):
    result = CliRunner().invoke(app, [*args, "--seed", "-1", "-o", str(tmp_path / "out")]
                                if args[0] not in ("robot-sim", "camera-sim") else [*args, "--seed", "-1"])
    assert result.exit_code == 2 and isinstance(result.exception, SystemExit), result.output
    assert "Invalid value for '--seed'" in result.output
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize("command", [["robot-sim", "--robot", "1"], ["camera-sim"]])
@pytest.mark.parametrize("option", [["--duration", "0"], ["--loss", "2"], ["--delay", "-1"], ["--jitter", "-1"]])
def test_simulated_team_options_are_named(command, option):
    result = CliRunner().invoke(app, [*command, *option])
    assert result.exit_code == 2 and isinstance(result.exception, SystemExit), result.output
    assert option[0] in result.output and "--preset" not in result.output


@pytest.mark.parametrize("option", [["--threads", "0"], ["--batch-size", "0"], ["--device", "gpu0"]])
def test_train_options_are_named(tmp_path, option):
    if option[0] == "--device":
        pytest.importorskip("torch", reason="train needs the 'train' extra")
    result = CliRunner().invoke(app, ["train", "--steps", "1", *option, "-o", str(tmp_path / "run")])
    assert result.exit_code == 2 and isinstance(result.exception, SystemExit), result.output
    assert option[0] in result.output


def test_track_pipeline_help_names_every_identifier():
    import re

    import typer

    from lookalike.vision.pipeline import IDENTIFIERS

    track = typer.main.get_command(app).commands["track"]
    (help_text,) = [p.help for p in track.params if p.name == "pipeline"]
    named = re.search(r"-t ([\w|]+)", help_text).group(1).split("|")
    assert sorted(named) == sorted(IDENTIFIERS)


@pytest.mark.parametrize("option", [["--publish", "127.0.0.1:7800"], ["--group", "239.255.77.1:7701"],
                                    ["--port-file", "port.txt"], ["--listen", "0.0.0.0:9000"], ["--no-reply"]])
def test_serve_over_dds_refuses_udp_options(tmp_path, option):
    args = [option[0], str(tmp_path / option[1])] if option[0] == "--port-file" else option
    result = CliRunner().invoke(app, ["serve", "--transport", "dds", "--duration", "0.1", *args])
    assert result.exit_code == 2 and isinstance(result.exception, SystemExit), result.output
    assert f"{option[0]}: with --transport udp only" in result.output
    assert not (tmp_path / "port.txt").exists()


@pytest.mark.parametrize("option", [["--duration", "-1"], ["--duration", "nan"], ["--status-interval", "-1"],
                                    ["--status-interval", "nan"]])
def test_serve_refuses_negative_or_nan_times(option):
    result = CliRunner().invoke(app, ["serve", "--listen", "127.0.0.1:0", *option])
    assert result.exit_code == 2 and isinstance(result.exception, SystemExit), result.output
    assert option[0].lstrip("-").split("-")[0] in result.output and "listening" not in result.output


@pytest.mark.parametrize("option", [["--robots", "0"], ["--robots", "300"], ["--max-report-age", "0"],
                                    ["--rate", "0"], ["--burst", "0.5"], ["--camera-timeout", "nan"],
                                    ["--transport", "dds", "--domain-id", "999"]])
def test_serve_names_the_option_of_a_value_out_of_range(option):
    result = CliRunner().invoke(app, ["serve", "--listen", "127.0.0.1:0", "--duration", "0.1", *option])
    assert result.exit_code == 2 and isinstance(result.exception, SystemExit), result.output
    assert f"{option[-2]})" in result.output or f"{option[-2]}:" in result.output, result.output


def test_serve_refuses_a_tracker_with_fewer_agents_than_robots():
    """Robot 2's reports would make every frame a tracker error: the node would never publish."""
    result = CliRunner().invoke(app, ["serve", "--listen", "127.0.0.1:0", "--duration", "0.1", "--robots", "3",
                                      "--set", "n_agents=2"])
    assert result.exit_code == 2 and isinstance(result.exception, SystemExit), result.output
    assert "--set n_agents=2: fewer than --robots 3" in result.output and "listening" not in result.output


def test_train_refuses_a_bad_protocol_before_making_its_output_folder(tmp_path):
    pytest.importorskip("torch", reason="train needs the 'train' extra")
    result = CliRunner().invoke(app, ["train", "--steps", "1", "--protocol", "bogus", "-o", str(tmp_path / "run")])
    assert result.exit_code == 2 and "--protocol: unknown protocol 'bogus'" in result.output, result.output
    assert not (tmp_path / "run").exists()


def test_a_simulated_team_too_long_for_memory_names_duration(monkeypatch):
    import lookalike.cli.node as node

    def too_big(*args, **kwargs):
        raise MemoryError("Unable to allocate 1.2 TiB")

    monkeypatch.setattr(node, "team_sequence", too_big)
    result = CliRunner().invoke(app, ["robot-sim", "--robot", "1", "--duration", "1e9"])
    assert result.exit_code == 2 and "--duration 1e+09: the simulated sequence does not fit in memory" in result.output


@pytest.mark.parametrize("option", [["--test", "."], ["--validation-fraction", "0.5"], ["--mix-sim", "0.2"]])
def test_train_refuses_fine_tuning_options_without_recordings(tmp_path, option):
    pytest.importorskip("torch", reason="train needs the 'train' extra")
    result = CliRunner().invoke(app, ["train", "--steps", "1", *option, "-o", str(tmp_path / "run")])
    assert result.exit_code == 2 and f"{option[0]}: only with --recordings" in result.output, result.output
    assert not (tmp_path / "run").exists()


@pytest.mark.parametrize(("mode", "option"), [
    (["--recordings", "."], ["--model", "set"]), (["--recordings", "."], ["--ship"]),
    (["--recordings", "."], ["--hidden", "8"]), (["--recordings", "."], ["--preset", "m10n7"]),
    (["--search", "1"], ["--init-from", "model.npz"]), (["--search", "1"], ["--learning-rate", "0.1"]),
    (["--search", "1"], ["--ship"]), (["--model", "set"], ["--hidden", "8"]),
    (["--model", "set"], ["--sequence-length", "300"]), (["--model", "set"], ["--init-from", "model.npz"]),
])
def test_train_refuses_options_its_kind_of_run_would_ignore(tmp_path, mode, option):
    """They were accepted and silently ignored (``--recordings --model set`` fine-tuned an LSTM, ``--search --ship``
    shipped nothing, ``--model set --hidden 8`` trained the default widths)."""
    pytest.importorskip("torch", reason="train needs the 'train' extra")
    result = CliRunner().invoke(app, ["train", "--steps", "1", *mode, *option, "-o", str(tmp_path / "run")])
    assert result.exit_code == 2 and isinstance(result.exception, SystemExit), result.output
    assert f"{option[0]}: not with {mode[0] if mode[0] != '--model' else '--model set'}" in result.output
    assert not (tmp_path / "run").exists()


@pytest.mark.parametrize(("args", "earlier"), [
    (["--sequence-length", "150"], "model.npz"), (["--sequence-length", "150"], "checkpoint.pt"),
    (["--model", "set"], "set.npz"), (["--recordings", "."], "model.npz"),
])
def test_train_refuses_to_start_over_an_earlier_run(tmp_path, args, earlier):
    """A new run into a folder holding an earlier run's weights replaced them at its first validation (hours of
    training lost to a command run again without --resume)."""
    pytest.importorskip("torch", reason="train needs the 'train' extra")
    run = tmp_path / "run"
    run.mkdir()
    (run / earlier).write_bytes(b"an earlier run's weights")
    result = CliRunner().invoke(app, ["train", "--steps", "1", "--batch-size", "1", *args, "-o", str(run)])
    assert result.exit_code == 2 and isinstance(result.exception, SystemExit), result.output
    assert f"holds an earlier run ({earlier})" in result.output and "--resume continues it" in result.output
    assert sorted(p.name for p in run.iterdir()) == [earlier]
    assert (run / earlier).read_bytes() == b"an earlier run's weights"


@pytest.mark.parametrize("option", [["--sampler", "random"], ["--space", "hidden=4:8"], ["--study", "sqlite:///s.db"]])
def test_train_refuses_search_options_without_search(tmp_path, option):
    """They were accepted and ignored: one training run, no search, no study."""
    pytest.importorskip("torch", reason="train needs the 'train' extra")
    result = CliRunner().invoke(app, ["train", "--steps", "1", "--sequence-length", "150", "--batch-size", "1",
                                      *option, "-o", str(tmp_path / "run")])
    assert result.exit_code == 2 and f"{option[0]}: only with --search" in result.output, result.output
    assert not (tmp_path / "run").exists() and not (tmp_path / "s.db").exists()


def test_train_resume_without_a_checkpoint_says_it_starts_a_new_run(tmp_path):
    """``--resume`` into a folder with nothing to continue (a mistyped -o) trained from scratch without a word."""
    pytest.importorskip("torch", reason="train needs the 'train' extra")
    result = CliRunner().invoke(app, ["train", "--steps", "1", "--sequence-length", "150", "--batch-size", "1",
                                      "--resume", "-o", str(tmp_path / "run")])
    assert result.exit_code == 0, result.output
    assert "--resume: " in result.output and "holds no checkpoint.pt to continue; starting a new run" in result.output


def test_train_ship_into_a_folder_it_cannot_write_is_one_line(tmp_path, monkeypatch):
    """It ended in a FileNotFoundError traceback after the training (the weights were kept, the message did not
    say where)."""
    pytest.importorskip("torch", reason="train needs the 'train' extra")
    import lookalike.trackers.lstm.weights as weights

    blocker = tmp_path / "a file"
    blocker.write_text("not a folder\n")
    monkeypatch.setattr(weights, "WEIGHTS_DIR", blocker / "weights")
    result = CliRunner().invoke(app, ["train", "--steps", "1", "--sequence-length", "150", "--batch-size", "1",
                                      "--ship", "-o", str(tmp_path / "run")])
    assert result.exit_code == 2 and isinstance(result.exception, SystemExit), result.output
    assert "--ship: cannot write" in result.output and f"{tmp_path / 'run' / 'model.npz'}" in result.output


def test_train_ship_replaces_the_shipped_pair_through_a_rename(tmp_path, monkeypatch):
    """The weights were copied into the package folder in place: a copy cut short left a half-written .npz under
    the shipped name."""
    pytest.importorskip("torch", reason="train needs the 'train' extra")
    import lookalike.trackers.lstm.weights as weights
    from lookalike.trackers.lstm import load_weights

    shipped = tmp_path / "weights" / "lstm_m3_n2.npz"
    shipped.parent.mkdir()
    shipped.write_bytes(b"earlier weights")
    os.link(shipped, tmp_path / "earlier.npz")  # a second name: a copy into the file itself changes it too
    monkeypatch.setattr(weights, "WEIGHTS_DIR", shipped.parent)
    result = CliRunner().invoke(app, ["train", "--steps", "1", "--sequence-length", "150", "--batch-size", "1",
                                      "--ship", "-o", str(tmp_path / "run")])
    assert result.exit_code == 0, result.output
    assert (tmp_path / "earlier.npz").read_bytes() == b"earlier weights"
    assert load_weights(shipped).spec.n_agents == 2
    assert sorted(p.name for p in shipped.parent.iterdir()) == ["lstm_m3_n2.json", "lstm_m3_n2.npz"]
