"""``bench ident`` shows a row for an LSTM whose shipped weights do not exist for a set-up, and goes on."""

from __future__ import annotations

from typer.testing import CliRunner

import lookalike.trackers.lstm.weights as weights
from lookalike.bench.ident import NOT_TRAINED, ident_table, weights_missing
from lookalike.bench.ident_paper import margin_rows
from lookalike.cli import app


def test_missing_weights_give_a_not_trained_row(tmp_path, monkeypatch):
    assert not weights_missing("lstm-paper", 2, 3) and not weights_missing("jpda", 7, 10)
    monkeypatch.setattr(weights, "WEIGHTS_DIR", tmp_path)  # nothing ships
    assert weights_missing("lstm-paper", 2, 3) and weights_missing("lstm", 2, 3)
    assert not weights_missing("kalman_ha", 2, 3)
    rows = ident_table(["m3n2"], ["lstm-paper", "kalman_ha"], sequences=1, frames=30)
    assert rows[0]["Success rate (%)"] == NOT_TRAINED and isinstance(rows[1]["Success rate (%)"], float)
    assert margin_rows(rows, ["m3n2"], ["M=3, N=2"]) == []
    res = CliRunner().invoke(app, ["bench", "ident", "--setups", "m3n2", "--trackers", "lstm-paper,kalman_ha",
                                   "--sequences", "1", "--frames", "30"])
    assert res.exit_code == 0, res.output
    assert NOT_TRAINED in res.output
