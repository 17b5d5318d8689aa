"""Hyper-parameter search (``lookalike train --search N``): trials draw inside the space, the study is saved
and continued, the choice is written beside the chosen weights. Tiny: 2-3 trials of 2 steps."""

import json

import pytest
from typer.testing import CliRunner

pytest.importorskip("torch", reason="training needs torch (the 'train' extra)")
pytest.importorskip("optuna", reason="the search needs optuna (the 'tune' extra)")

from lookalike.learn.search import SearchSpace, run_search  # noqa: E402
from lookalike.learn.training import TrainConfig  # noqa: E402
from lookalike.sim import preset  # noqa: E402

SPACE = SearchSpace(hidden=(4, 8), layers=(1, 2), learning_rate=(1e-3, 1e-2))


def _base() -> TrainConfig:
    world = preset("m3n2")
    return TrainConfig(n_agents=world.n_agents, n_slots=world.max_detections, batch_size=2, sequence_length=150,
                       steps=2, validation_every=1, validation_sequences=2)


def test_search_saves_the_study_continues_it_and_records_the_choice(tmp_path):
    rows = []
    result = run_search(_base(), preset("m3n2"), tmp_path, 2, space=SPACE, sampler="random", check_sequences=2,
                        progress=lambda done, total, row: rows.append(row))
    assert result.trials == 2 and [r["trial"] for r in rows] == [0, 1]
    for r in rows:
        assert 4 <= r["hidden"] <= 8 and 1 <= r["num_layers"] <= 2 and 1e-3 <= r["learning_rate"] <= 1e-2
    summary = json.loads(result.summary_path.read_text())
    assert summary["chosen"] == result.params and 0.0 <= summary["check_success"] <= 1.0
    assert result.weights_path.is_file() and result.weights_path.with_suffix(".json").is_file()
    assert (tmp_path / "search.db").is_file()
    more = run_search(_base(), preset("m3n2"), tmp_path, 3, space=SPACE, sampler="random", check_sequences=2,
                      progress=lambda done, total, row: rows.append(row))
    assert more.trials == 3 and [r["trial"] for r in rows] == [0, 1, 2]  # only the missing trial ran
    with pytest.raises(ValueError, match=r"other settings: steps 2 \(now 3\); continue it"):
        run_search(TrainConfig(**{**_base().__dict__, "steps": 3}), preset("m3n2"), tmp_path, 4, space=SPACE)


def test_an_interrupted_trial_runs_again_and_is_not_counted_as_a_failure(tmp_path):
    """A trial cut short by Ctrl-C counted as one of the N trials and as 'failed': --search 3 after an interruption
    gave 2 finished trials and said 1 failed."""
    import optuna

    run_search(_base(), preset("m3n2"), tmp_path, 1, space=SPACE, sampler="random", check_sequences=2)
    study = optuna.load_study(study_name="lstm", storage=f"sqlite:///{tmp_path / 'search.db'}")
    cut_short = study.ask()  # a trial left running, as Ctrl-C leaves it
    SPACE.suggest(cut_short)
    rows = []
    result = run_search(_base(), preset("m3n2"), tmp_path, 3, space=SPACE, sampler="random", check_sequences=2,
                        progress=lambda done, total, row: rows.append(row))
    assert result.trials == 3 and result.failed == 0
    assert [r["trial"] for r in rows] == [2, 3] and rows[0]["hidden"] == cut_short.params["hidden"]
    assert json.loads(result.summary_path.read_text())["failed"] == 0


def test_train_search_command(tmp_path):
    from lookalike.cli import app

    r = CliRunner().invoke(app, ["train", "--search", "2", "--preset", "m3n2", "-o", str(tmp_path), "--steps", "1",
                                 "--sequence-length", "150", "--batch-size", "2", "--sampler", "random",
                                 "--space", "hidden=4:8,layers=1:1"])
    assert r.exit_code == 0, r.output
    assert "chosen: hidden" in r.output and (tmp_path / "search.json").is_file()
    bad = CliRunner().invoke(app, ["train", "--search", "1", "-o", str(tmp_path / "b"), "--sampler", "grid"])
    assert bad.exit_code == 2 and "--sampler" in bad.output
    bad = CliRunner().invoke(app, ["train", "--search", "1", "-o", str(tmp_path / "b"), "--space", "depth=1:2"])
    assert bad.exit_code == 2 and "depth=1:2" in bad.output
