"""Tracker parameters declare their ranges (``param(..., range=...)``); every registered tracker's config
checks them at construction, ``--set`` and ``make_tracker`` refuse values outside them in one line, and
``lookalike tune``'s search spaces stay inside them."""

import math
import re
import typing

import numpy as np
import pytest
from typer.testing import CliRunner

from lookalike.cli import app
from lookalike.trackers import make_tracker, tracker_class, tracker_names, tracker_parameters
from lookalike.trackers.base import Range, check_params
from lookalike.trackers.registry import parse_parameter
from lookalike.tune.space import default_space, grid, searched

runner = CliRunner()


def _numeric(tracker):
    hints = typing.get_type_hints(tracker_class(tracker).Config)
    for p in tracker_parameters(tracker):
        args = [a for a in typing.get_args(hints[p.name]) if a is not type(None)]
        kind = args[0] if args else hints[p.name]
        if kind in (int, float):
            yield p, kind


@pytest.mark.parametrize("tracker", tracker_names())
def test_every_number_declares_a_range_holding_its_default(tracker):
    for p, _ in _numeric(tracker):
        assert isinstance(p.range, Range), (tracker, p.name)
        assert p.default is None or p.default in p.range, (tracker, p.name, p.default, p.range)
    check_params(tracker_class(tracker).Config())  # the defaults pass


def _outside(r: Range, kind: type) -> list[float]:
    """Values just outside ``r`` (or on an open end)."""
    out: list[float] = []
    if r.low is not None:
        out.append(r.low if r.low_open else (r.low - 1 if kind is int else r.low - 1e-6))
    if r.high is not None:
        out.append(r.high if r.high_open else (r.high + 1 if kind is int else r.high * 1.001 + 1e-6))
    return [int(v) if kind is int else float(v) for v in out]


@pytest.mark.parametrize("tracker", tracker_names())
def test_direct_construction_checks_ranges_and_finiteness(tracker):
    config = tracker_class(tracker).Config
    for p, kind in _numeric(tracker):
        for bad in _outside(p.range, kind):
            with pytest.raises(ValueError, match=rf"tracker '{tracker}': {p.name}=.* is out of range"):
                config(**{p.name: bad})
        if kind is float:
            for bad in (math.nan, math.inf):
                with pytest.raises(ValueError, match=rf"{p.name}=.* must be a finite number"):
                    config(**{p.name: bad})


# Range ends refused for a reason of their own, each in a message naming the parameter: another parameter's default
# (boxtrack's scores, the k-of-n confirmation) or the LSTM's shipped weights (sizes it was trained for).
_ENDS_OF_THEIR_OWN = {("boxtrack", "high_score"), ("boxtrack", "low_score"), ("jpda", "confirm_hits"),
                      ("jpda", "confirm_window"), ("kalman_ha2", "confirm_hits"), ("kalman_ha2", "confirm_window"),
                      ("lstm", "n_agents"), ("lstm", "n_slots")}


@pytest.mark.parametrize("tracker", tracker_names())
def test_every_allowed_range_end_builds_the_tracker(tracker):
    for p, kind in _numeric(tracker):
        if (tracker, p.name) in _ENDS_OF_THEIR_OWN:
            continue
        r = p.range
        ends = [v for v, is_open in ((r.low, r.low_open), (r.high, r.high_open)) if v is not None and not is_open]
        for value in ends:
            make_tracker(tracker, **{p.name: kind(value)})


def test_make_tracker_names_the_tracker_parameter_and_expectation():
    with pytest.raises(TypeError, match=r"^tracker 'sort': max_age='3' must be an int$"):
        make_tracker("sort", max_age="3")
    with pytest.raises(ValueError, match=r"^tracker 'sort': iou_threshold=7 is out of range \[0, 1\]$"):
        make_tracker("sort", iou_threshold=7)
    with pytest.raises(ValueError, match="iou_threshold=nan must be a finite number"):
        make_tracker("sort", iou_threshold=float("nan"))
    with pytest.raises(TypeError, match="max_age=True must be an int"):
        make_tracker("sort", max_age=True)
    with pytest.raises(TypeError, match="max_age=None must be an int"):
        make_tracker("sort", max_age=None)
    with pytest.raises(ValueError, match=r"gate_probability=1.0 is out of range \(0, 1\)"):
        make_tracker("deepsort", gate_probability=1.0)
    # numpy numbers and ints for floats are fine
    assert make_tracker("sort", max_age=np.int64(3), iou_threshold=1).config.iou_threshold == 1


def test_an_unknown_tracker_name_is_a_value_error_listing_the_known_ones():
    """A bad name is bad input like a bad parameter: ``ValueError`` (still a ``KeyError``, as it was), its text the
    plain message."""
    for build in (make_tracker, tracker_class, tracker_parameters):
        with pytest.raises(ValueError, match=r"^unknown tracker 'nosuch'; registered: .*\bsort\b") as info:
            build("nosuch")
        assert isinstance(info.value, KeyError)


def test_parse_parameter_checks_the_range():
    assert parse_parameter("sort", "iou_threshold=0.5") == ("iou_threshold", 0.5)
    for text, message in (("iou_threshold=7", "out of range [0, 1]"), ("iou_threshold=nan", "finite"),
                          ("iou_threshold=-inf", "finite"), ("max_age=-1", "out of range [0, 1000000000]")):
        with pytest.raises(ValueError, match=re.escape(message)):
            parse_parameter("sort", text)


@pytest.mark.parametrize("value", ["7", "nan", "-0.1"])
def test_track_set_out_of_range_exits_2_in_one_line(tmp_path, value):
    det = tmp_path / "det.txt"
    det.write_text("1,-1,10,10,20,40,0.9,-1,-1,-1\n")
    out = tmp_path / "o.txt"
    r = runner.invoke(app, ["track", str(det), "-o", str(out), "--set", f"iou_threshold={value}"])
    assert r.exit_code == 2, r.output
    lines = [line for line in r.output.splitlines() if line.strip()]
    assert len(lines) == 1 and "tracker 'sort': iou_threshold=" in lines[0], r.output
    assert not out.exists()


def test_trackers_lists_the_ranges():
    r = runner.invoke(app, ["trackers", "--details", "boxtrack"], env={"COLUMNS": "200"})
    assert r.exit_code == 0, r.output
    assert "allowed" in r.output and "[0, 1]" in r.output and "(0, inf)" in r.output


@pytest.mark.parametrize("tracker", tracker_names())
def test_tune_spaces_fall_inside_the_declared_ranges(tracker):
    params = {p.name: p for p in tracker_parameters(tracker)}
    for name, dim in searched(default_space(tracker)).items():
        r = params[name].range
        values = [v for v in grid(dim, 7) if v is not None]
        if dim.kind != "choice":
            values += [dim.low, dim.high]
        for v in values:
            assert r is None or v in r, (tracker, name, v, r)
