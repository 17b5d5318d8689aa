"""``bench ident --weights`` runs our protocol's LSTM rows on other weights (e.g. a training run's)."""

from __future__ import annotations

import shutil

import pytest
from typer.testing import CliRunner

import lookalike.trackers.lstm.weights as weights
from lookalike.bench.ident import ident_table, uses_weights, weights_missing
from lookalike.cli import app


def test_weights_replace_the_shipped_ones_for_lstm_rows_only(tmp_path, monkeypatch):
    shipped = weights.shipped_weights_path(2, 3)
    copy = tmp_path / "run" / "model.npz"
    copy.parent.mkdir()
    shutil.copy(shipped, copy)
    shutil.copy(shipped.with_suffix(".json"), copy.with_suffix(".json"))
    assert uses_weights("lstm") and uses_weights("lstm-lowpass") and not uses_weights("lstm-paper")
    assert not uses_weights("jpda")
    names = ["lstm", "lstm-lowpass"]
    before = ident_table(["m3n2"], names, sequences=1, frames=40)
    monkeypatch.setattr(weights, "WEIGHTS_DIR", tmp_path / "none")  # nothing ships: the rows use the copy
    assert weights_missing("lstm", 2, 3) and not weights_missing("lstm", 2, 3, str(copy))
    after = ident_table(["m3n2"], names, sequences=1, frames=40, weights=str(copy))
    strip = lambda rows: [{k: v for k, v in r.items() if k != "Frames/s"} for r in rows]  # noqa: E731
    assert strip(after) == strip(before)
    with pytest.raises(ValueError, match="one set-up"):
        ident_table(["m3n2", "m5n3"], ["lstm"], sequences=1, frames=5, weights=str(copy))


def test_cli_weights_errors_are_one_line(tmp_path):
    runner = CliRunner()
    res = runner.invoke(app, ["bench", "ident", "--setups", "m3n2", "--trackers", "lstm", "--sequences", "1",
                              "--frames", "5", "--weights", str(tmp_path / "missing.npz")])
    assert res.exit_code == 2 and "missing.npz" in res.output
    res = runner.invoke(app, ["bench", "ident", "--setups", "m3n2", "--trackers", "lstm", "--sequences", "1",
                              "--frames", "5", "--weights", str(weights.shipped_weights_path(3, 5))])
    assert res.exit_code == 2 and "n_agents" in res.output


def test_weights_no_row_uses_are_refused_not_ignored(tmp_path):
    from lookalike.bench.ident import check_weights

    model = str(weights.shipped_weights_path(2, 3))
    res = CliRunner().invoke(app, ["bench", "ident", "--setups", "m3n2", "--trackers", "kalman_ha,lstm-paper",
                                   "--sequences", "1", "--frames", "5", "--weights", model])
    assert res.exit_code == 2 and res.output.startswith("error: weights:"), res.output
    assert "for the lstm and lstm-lowpass rows; none of kalman_ha, lstm-paper uses them" in res.output
    with pytest.raises(ValueError, match="none of jpda uses them"):  # bench pixels' check too
        check_weights(model, ["m3n2"], ["jpda"])
    check_weights(model, ["m3n2"], ["jpda", "lstm-lowpass"])
    check_weights(None, ["m3n2", "m5n3"], ["jpda"])
