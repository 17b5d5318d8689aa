"""lookalike.tune: studies, parameter files, leave-one-out selection and the CLI on simulated data."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from lookalike.bench.datasets import RealSequence
from lookalike.eval import headline
from lookalike.io import MotTable, write_mot
from lookalike.sim.boxes import BoxSceneConfig, simulate_boxes
from lookalike.tune import (
    Dim,
    Fold,
    check_params,
    default_space,
    evaluate_table,
    k_folds,
    leave_one_group_out,
    load_params,
    make_folds,
    one_at_a_time,
    parameter_gains,
    read_params,
    sample,
    save_params,
    score_params,
    select_from_table,
    space_from_json,
    space_to_json,
)
from lookalike.tune.space import grid


def _scene(seed: int, frames: int = 40):
    return simulate_boxes(BoxSceneConfig(n_targets=3, frames=frames, seed=seed))


def _sequence(seed: int, frames: int = 40) -> RealSequence:
    scene = _scene(seed, frames)
    return RealSequence("sim", f"s{seed}", 25.0, frames, [f.detections.xywh for f in scene.frames],
                        [f.detections.score for f in scene.frames], gt=MotTable.from_rows(scene.gt),
                        image_size=(640, 480))


@pytest.fixture(scope="module")
def sequences() -> list[RealSequence]:
    return [_sequence(i) for i in range(3)]


# -- spaces, folds, parameter files (no optuna needed) ------------------------------------------------


def test_default_spaces_name_real_parameters():
    from lookalike.trackers import tracker_parameters
    from lookalike.tune import DEFAULT_SPACES

    for tracker in ("sort", "boxtrack"):
        known = {p.name for p in tracker_parameters(tracker)}
        assert set(DEFAULT_SPACES[tracker]) <= known, set(DEFAULT_SPACES[tracker]) - known
    assert default_space("boxtrack")["max_age_s"].log  # scale-like: log space
    assert not default_space("boxtrack")["high_score"].log  # a fraction: linear


def test_generic_space_from_defaults():
    space = default_space("kalman_ha")  # no declared space: built from the defaults
    assert space and all(isinstance(d, Dim) for d in space.values())
    assert "frame_interval_s" not in space


def test_space_json_round_trip_and_errors():
    space = default_space("boxtrack")
    again = space_from_json(json.loads(json.dumps(space_to_json(space))), "boxtrack")
    assert again == space
    fixed = space_from_json({"n_init": 2, "max_age_s": {"low": 0.5, "high": 2, "log": True}}, "boxtrack")
    assert fixed["n_init"] == 2 and fixed["max_age_s"].log
    with pytest.raises(ValueError, match="no parameter 'nope'"):
        space_from_json({"nope": {"low": 0, "high": 1}}, "boxtrack")
    with pytest.raises(ValueError, match="log-scale"):
        space_from_json({"max_age_s": {"low": 0, "high": 1, "log": True}}, "boxtrack")


def test_sample_and_grid_stay_in_range():
    rng = np.random.default_rng(0)
    space = default_space("boxtrack")
    for _ in range(50):
        params = sample(space, rng)
        for name, dim in space.items():
            v = params[name]
            if v is None:
                assert dim.optional
            elif dim.kind == "choice":
                assert v in dim.choices
            else:
                assert dim.low <= v <= dim.high
    assert grid(Dim("int", 1, 5), 3) == [1, 3, 5]
    values = grid(Dim("float", 0.1, 10.0, log=True, optional=True), 3)
    assert values[:3] == pytest.approx([0.1, 1.0, 10.0]) and values[3] is None


def test_folds():
    assert [f.test for f in leave_one_group_out(["a", "b", "c"])] == [(0,), (1,), (2,)]
    lodo = make_folds(["x/1", "x/2", "y/1"], "lodo", ["x", "x", "y"])
    assert [(f.train, f.test) for f in lodo] == [((2,), (0, 1)), ((0, 1), (2,))]
    assert [f.test for f in k_folds(list("abcde"), 2)] == [(0, 2, 4), (1, 3)]
    with pytest.raises(ValueError, match="at least two"):
        make_folds(["only"], "loso")
    with pytest.raises(ValueError, match="loso"):
        make_folds(["a", "b"], "often")


def test_parameter_file_round_trip(tmp_path: Path):
    path = save_params(tmp_path / "p.json", "boxtrack", {"n_init": 2, "clutter_factor": None, "max_age_s": 1.5},
                       chosen_on=["sim/s0", "sim/s1"], criterion="hota+idf1+mota", trials=7, score=1.23)
    data = json.loads(path.read_text())
    assert {"tracker", "params", "chosen_on", "criterion", "trials", "lookalike_version"} <= set(data)
    assert load_params(path, "boxtrack") == {"n_init": 2, "clutter_factor": None, "max_age_s": 1.5}
    content = read_params(path)
    assert content.chosen_on == ["sim/s0", "sim/s1"] and content.trials == 7 and content.extra["score"] == 1.23


def test_parameter_file_refused_with_clear_errors(tmp_path: Path):
    path = save_params(tmp_path / "p.json", "sort", {"max_age": 3}, chosen_on=[], criterion="hota", trials=1)
    with pytest.raises(ValueError, match="for tracker 'sort', not 'boxtrack'"):
        load_params(path, "boxtrack")
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps({"tracker": "nosuch", "params": {}}))
    with pytest.raises(ValueError, match="unknown tracker 'nosuch'"):
        load_params(bad)
    bad.write_text(json.dumps({"tracker": "sort", "params": {"max_agee": 3}}))
    with pytest.raises(ValueError, match="no parameter.*max_agee"):
        load_params(bad, "sort")
    bad.write_text(json.dumps({"tracker": "sort", "params": {"max_age": -1}}))
    with pytest.raises(ValueError, match="refuses"):
        load_params(bad, "sort")
    bad.write_text("not json")
    with pytest.raises(ValueError, match="not a JSON parameter file"):
        load_params(bad)
    with pytest.raises(ValueError, match="not found"):
        load_params(tmp_path / "missing.json")
    bad.write_bytes(b"\x00\x00\x00\x18ftypmp42\xe8\xff")  # a video given by mistake
    with pytest.raises(ValueError, match=r"bad\.json:1: not UTF-8 text"):
        load_params(bad)
    with pytest.raises(ValueError, match="is a folder, not a parameter file"):
        load_params(tmp_path)
    # hand-edited bookkeeping fields: were an OverflowError or TypeError naming no file
    for extra, message in (({"trials": 1e400}, "'trials' must be a whole number"),
                           ({"trials": None}, "'trials' must be a whole number"),
                           ({"chosen_on": 5}, "'chosen_on' must be a list")):
        bad.write_text(json.dumps({"tracker": "sort", "params": {}, **extra}).replace("Infinity", "1e400"))
        with pytest.raises(ValueError, match=f"bad.json: {message}"):
            load_params(bad)
    bad.write_text("[" * 100_000 + "]" * 100_000)  # was a RecursionError
    with pytest.raises(ValueError, match="bad.json: not a JSON parameter file"):
        load_params(bad)
    bad.write_text(json.dumps({"tracker": "sort", "params": {}, "trials": 60.0}))
    assert read_params(bad).trials == 60


def test_tune_space_file_that_is_binary_is_named(tmp_path: Path):
    from typer.testing import CliRunner

    from lookalike.cli import app

    space = tmp_path / "space.json"
    space.write_bytes(b"\xe8\xff{}")
    r = CliRunner().invoke(app, ["tune", "-t", "boxtrack", str(tmp_path), "--space", str(space)])
    assert r.exit_code == 2 and "--space: " in r.output and "space.json:1: not UTF-8 text" in r.output, r.output
    for text in ("[" * 100_000 + "]" * 100_000, "{not json"):  # a RecursionError traceback; a message naming no file
        space.write_text(text)
        r = CliRunner().invoke(app, ["tune", "-t", "boxtrack", str(tmp_path), "--space", str(space)])
        assert r.exit_code == 2 and f"--space: {space}: not a JSON search space" in r.output, r.output
    with pytest.raises(ValueError, match="no parameter"):
        check_params("boxtrack", {"speed": 1})


def test_tune_refuses_an_unknown_metric_before_loading_anything(tmp_path: Path):
    pytest.importorskip("optuna")
    from typer.testing import CliRunner

    from lookalike.cli import app

    r = CliRunner().invoke(app, ["tune", str(tmp_path / "nothing-here"), "--metric", "idf2", "-o",
                                 str(tmp_path / "p.json")])
    assert r.exit_code == 2 and "--metric: expected one of hota+idf1+mota, hota, idf1, got 'idf2'" in r.output, r.output
    assert "sequence(s)" not in r.output


# -- selection never looks at the left-out sequence ----------------------------------------------------


def test_table_selection_ignores_the_left_out_sequence(monkeypatch):
    # candidate 1 is by far the best on sequence "a" only; candidate 0 is best on "b" and "c".
    # A fold that looked at its left-out sequence would pick candidate 1 when "a" is left out.
    import sys

    objective_module, selection = sys.modules["lookalike.tune.objective"], sys.modules["lookalike.tune.selection"]

    def mean(rows):
        return {"v": sum(r["v"] for r in rows) / len(rows)}

    monkeypatch.setattr(objective_module, "combine", mean)
    monkeypatch.setattr(selection, "combine", mean)
    monkeypatch.setitem(objective_module.CRITERIA, "v", lambda s: s["v"])
    good, bad = 0.9, 0.1
    table = [[{"v": bad}, {"v": good}, {"v": good}],
             [{"v": 100.0}, {"v": bad}, {"v": bad}]]
    keys = ["a", "b", "c"]
    choices = select_from_table(table, leave_one_group_out(keys), keys, metric="v")
    assert [c.candidate for c in choices] == [0, 1, 1]
    assert choices[0].left_out == ["a"] and choices[0].chosen_on == ["b", "c"]
    assert choices[0].test_value == bad  # the left-out figure is what the choice gets there


def test_leave_one_out_selection_never_runs_the_left_out_sequence_in_its_study(sequences):
    pytest.importorskip("optuna")
    from lookalike.tune import leave_one_out_selection

    events: list[tuple[str, ...]] = []

    def evaluate(tracker: str, params: dict, seq: RealSequence) -> dict[str, float]:
        events.append(("run", f"sim/{seq.name}"))
        return score_params(tracker, params, seq)

    def progress(fold: str, done: int, total: int, best: float | None) -> None:
        events.append(("trial", fold, str(done)))

    trials = 3
    choices = leave_one_out_selection("sort", sequences, trials=trials, sampler="random", evaluator=evaluate,
                                      progress=progress)
    assert [c.left_out for c in choices] == [["sim/s0"], ["sim/s1"], ["sim/s2"]]
    pos = 0
    for c in choices:
        study_runs = []
        for _ in range(trials):  # each trial runs the training sequences, then reports progress
            while events[pos][0] == "run":
                study_runs.append(events[pos][1])
                pos += 1
            assert events[pos] == ("trial", c.fold, str(_ + 1))
            pos += 1
        assert sorted(set(study_runs)) == sorted(c.chosen_on)
        assert c.left_out[0] not in study_runs  # the study never ran the left-out sequence
        assert events[pos] == ("run", c.left_out[0])  # which is run once, with the chosen parameters
        pos += 1
        seq = sequences[[f"sim/{s.name}" for s in sequences].index(c.left_out[0])]
        assert c.test_value == pytest.approx(headline(score_params("sort", c.params, seq)))
    assert pos == len(events)


# -- studies ------------------------------------------------------------------------------------------


def test_study_runs_saves_and_resumes(sequences, tmp_path: Path):
    optuna = pytest.importorskip("optuna")
    from lookalike.tune import run_study

    storage = f"sqlite:///{tmp_path / 'study.db'}"
    first = run_study("sort", sequences, trials=3, sampler="random", storage=storage)
    assert first.trials == 3 and first.default_value is not None and first.value >= first.default_value
    with pytest.raises(ValueError, match="--resume"):
        run_study("sort", sequences, trials=3, storage=storage)
    done: list[int] = []
    again = run_study("sort", sequences, trials=5, sampler="random", storage=storage, resume=True,
                      progress=lambda d, t, b: done.append(d))
    assert done == [4, 5] and again.trials == 5 and again.value >= first.value
    study = optuna.load_study(study_name="sort", storage=storage)
    assert len(study.trials) == 5
    trial = study.trials[0]
    assert set(trial.user_attrs["params"]) == {"max_age", "min_hits", "iou_threshold"}
    assert set(trial.user_attrs["scores"]) == {"sim/s0", "sim/s1", "sim/s2"}
    with pytest.raises(ValueError, match="another sequences"):
        run_study("sort", sequences[:2], trials=6, storage=storage, resume=True)


def test_study_best_params_reproduce_its_value(sequences):
    pytest.importorskip("optuna")
    from lookalike.eval import combine
    from lookalike.tune import run_study

    result = run_study("boxtrack", sequences, trials=4, sampler="tpe")
    rerun = combine([score_params("boxtrack", result.params, s) for s in sequences])
    assert headline(rerun) == pytest.approx(result.value)


def test_failed_trials_do_not_stop_the_study(sequences):
    pytest.importorskip("optuna")
    from lookalike.tune import run_study

    space = {"max_age": Dim("int", -3, -1), "min_hits": 1}  # every drawn max_age is refused
    with pytest.raises(ValueError, match="no trial completed"):
        run_study("sort", sequences[:1], space=space, trials=2)


# -- one parameter at a time ---------------------------------------------------------------------------


def test_parameter_gains_on_a_table(sequences):
    space = {"max_age": Dim("int", 1, 30, log=True), "min_hits": Dim("int", 1, 5)}
    cands, by_param = one_at_a_time("sort", space, 2)
    assert cands[0] == {} and set(by_param) == {"max_age", "min_hits"}
    table = evaluate_table("sort", cands, sequences, score_params)
    keys = [f"sim/{s.name}" for s in sequences]
    gains = parameter_gains(table, cands, by_param, leave_one_group_out(keys), keys)
    assert {g.name for g in gains} == {"max_age", "min_hits"}
    for g in gains:
        assert len(g.gains) == 3 and g.verdict in ("keep", "fix", "drop")


# -- the command --------------------------------------------------------------------------------------


def _write_motchallenge(folder: Path, seed: int, frames: int = 30) -> None:
    scene = _scene(seed, frames)
    (folder / "gt").mkdir(parents=True)
    (folder / "det").mkdir()
    (folder / "seqinfo.ini").write_text(f"[Sequence]\nname={folder.name}\nframeRate=25\nseqLength={frames}\n"
                                        "imWidth=640\nimHeight=480\n")
    write_mot(folder / "gt" / "gt.txt", scene.gt)
    rows = []
    for f in scene.frames:
        d = f.detections
        for box, score in zip(d.xywh, d.score):
            rows.append([f.index + 1, -1, *box, score, -1, -1, -1])
    write_mot(folder / "det" / "det.txt", np.array(rows))


def test_cli_tune_on_a_motchallenge_folder(tmp_path: Path):
    pytest.importorskip("optuna")
    from typer.testing import CliRunner

    from lookalike.cli import app

    data = tmp_path / "mydata"
    for seed in (1, 2):
        _write_motchallenge(data / f"seq{seed}", seed)
    out = tmp_path / "params.json"
    db = f"sqlite:///{tmp_path / 'study.db'}"
    result = CliRunner().invoke(app, ["tune", "-t", "sort", str(data), "-o", str(out), "--trials", "3",
                                      "--sampler", "random", "--folds", "loso", "--study", db])
    assert result.exit_code == 0, result.output
    content = read_params(out)
    assert content.tracker == "sort" and content.trials == 3
    assert content.chosen_on == ["mydata/seq1", "mydata/seq2"]
    assert len(content.extra["left_out"]["per_fold"]) == 2
    assert load_params(out, "sort") == content.params
    resumed = CliRunner().invoke(app, ["tune", "-t", "sort", str(data), "-o", str(out), "--trials", "4",
                                       "--sampler", "random", "--study", db, "--resume"])
    assert resumed.exit_code == 0, resumed.output
    assert read_params(out).trials == 4
    refused = CliRunner().invoke(app, ["tune", "-t", "nosuch", str(data), "-o", str(out)])
    assert refused.exit_code == 2 and "unknown tracker" in refused.output


def test_cli_tune_refuses_data_without_ground_truth(tmp_path: Path):
    from typer.testing import CliRunner

    from lookalike.cli import app

    result = CliRunner().invoke(app, ["tune", "-t", "sort", str(tmp_path / "none"), "-o", str(tmp_path / "p.json")])
    assert result.exit_code == 2
    assert "neither a folder nor a bench dataset" in result.output


def test_folds_are_explicit_objects():
    fold = Fold("x", (0, 1), (2,))
    assert fold.train == (0, 1) and fold.test == (2,)


def test_cli_space_file_and_show_space(tmp_path: Path):
    from typer.testing import CliRunner

    from lookalike.cli import app

    shown = CliRunner().invoke(app, ["tune", "-t", "boxtrack", "--show-space"])
    assert shown.exit_code == 0 and '"max_age_s"' in shown.output and '"log": true' in shown.output
    bad = tmp_path / "space.json"
    bad.write_text(json.dumps({"speed": {"low": 1, "high": 2}}))
    refused = CliRunner().invoke(app, ["tune", "-t", "sort", "--space", str(bad), "--show-space"])
    assert refused.exit_code == 2 and "no parameter 'speed'" in refused.output


def test_cli_tune_with_a_space_file(tmp_path: Path):
    pytest.importorskip("optuna")
    from typer.testing import CliRunner

    from lookalike.cli import app

    data = tmp_path / "d"
    _write_motchallenge(data / "a", 3)
    space = tmp_path / "space.json"
    space.write_text(json.dumps({"max_age": {"low": 1, "high": 8, "type": "int", "log": True}, "min_hits": 2}))
    out = tmp_path / "p.json"
    result = CliRunner().invoke(app, ["tune", "-t", "sort", str(data / "a"), "-o", str(out), "--trials", "2",
                                      "--space", str(space), "--sampler", "random"])
    assert result.exit_code == 0, result.output
    params = load_params(out, "sort")
    assert params["min_hits"] == 2 and 1 <= params["max_age"] <= 8 and set(params) == {"max_age", "min_hits"}
