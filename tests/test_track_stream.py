"""The streaming frame loop: ``lookalike.loop.run``, lazy detection files and atomic streamed output."""

from __future__ import annotations

import gc
import weakref
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from lookalike.cli import app
from lookalike.io import DetectionStream, MotWriter, frames_from_table, read_mot, write_mot
from lookalike.loop import RowCollector, RunStats, run
from lookalike.trackers import make_tracker
from lookalike.types import Detections, Frame

runner = CliRunner()


def _det_file(path: Path, frames: int = 60, seed: int = 0, shuffle: bool = False) -> Path:
    rng = np.random.default_rng(seed)
    rows = []
    for k in range(1, frames + 1):
        if k % 7 == 0:
            continue  # frames without detections
        for i in range(3):
            x, y = 50 + 80 * i + 2 * k + rng.normal(), 100 + k + rng.normal()
            rows.append([k, -1, x, y, 30, 60, rng.uniform(0.2, 1.0), -1, -1, -1])
    data = np.array(rows)
    if shuffle:
        data = data[rng.permutation(len(data))]
    np.savetxt(path, data, fmt="%.3f", delimiter=",")
    return path


def _same_frames(a: list[Frame], b: list[Frame]) -> None:
    assert len(a) == len(b)
    for x, y in zip(a, b):
        assert (x.index, x.time) == (y.index, y.time)
        assert np.array_equal(x.detections.xywh, y.detections.xywh)
        assert np.array_equal(x.detections.score, y.detections.score)


@pytest.mark.parametrize("length", [None, 75])
@pytest.mark.parametrize("min_score", [-np.inf, 0.5])
@pytest.mark.parametrize("chunk", [5, 8192])
def test_stream_yields_the_frames_of_the_whole_table(tmp_path, length, min_score, chunk):
    path = _det_file(tmp_path / "det.txt")
    expected = list(frames_from_table(read_mot(path), length, 25.0, min_score))
    _same_frames(list(DetectionStream(path, length, 25.0, min_score, chunk_lines=chunk)), expected)


@pytest.mark.parametrize("chunk", [5, 8192])
def test_a_frame_past_the_length_is_an_error_naming_the_line(tmp_path, chunk):
    path = _det_file(tmp_path / "det.txt")
    frames = [int(float(line.split(",")[0])) for line in path.read_text().splitlines()]
    line = next(i for i, f in enumerate(frames, start=1) if f > 40)
    with pytest.raises(ValueError, match=rf"det.txt:{line}: invalid frame: frame {frames[line - 1]} > 40 \(seqLength"):
        DetectionStream(path, 40, 25.0, chunk_lines=chunk, length_name="seqLength in seqinfo.ini").check()


def test_unsorted_file_falls_back_to_reading_it_whole(tmp_path):
    path = _det_file(tmp_path / "det.txt", shuffle=True)
    expected = list(frames_from_table(read_mot(path), None, 30.0))
    _same_frames(list(DetectionStream(path, chunk_lines=4)), expected)


def test_malformed_file_fails_before_any_frame_with_read_mots_message(tmp_path):
    path = _det_file(tmp_path / "det.txt")
    lines = path.read_text().splitlines()
    lines[30] = lines[30].replace(",30.000,", ",-3.000,")  # a negative width
    path.write_text("\n".join(lines) + "\n")
    with pytest.raises(ValueError) as expected:
        read_mot(path, positive_size=True)
    with pytest.raises(ValueError) as got:
        DetectionStream(path, chunk_lines=8).check()
    assert str(got.value) == str(expected.value) and ":31:" in str(got.value)


def test_loop_keeps_no_frame_and_no_row():
    """Every frame is released once the sink has seen it: memory does not grow with the frames."""
    refs: list[weakref.ref] = []
    seen = {"frames": 0, "rows": 0}

    def frames():
        for k in range(2000):
            det = Detections(xywh=np.array([[10.0 + k % 50, 20.0, 30.0, 60.0]]), score=np.array([0.9]))
            frame = Frame(index=k, time=k / 30.0, detections=det)
            refs.append(weakref.ref(frame.detections))
            yield frame

    def counting_sink(frame, tracks):
        seen["frames"] += 1
        seen["rows"] += sum(1 for t in tracks if t.xywh is not None)

    stats = run(make_tracker("sort"), frames(), counting_sink)
    gc.collect()
    assert stats.frames == seen["frames"] == 2000 and seen["rows"] > 1500
    assert sum(r() is not None for r in refs) <= 1  # at most the last frame is still referenced


def test_run_accumulates_stats_over_sequences():
    stats = RunStats()
    for _ in range(2):
        run(make_tracker("sort"), (Frame(index=k, time=k / 10, detections=Detections.empty()) for k in range(5)),
            stats=stats)
    assert stats.frames == 10 and stats.seconds >= 0


def test_streamed_rows_equal_rows_written_at_once(tmp_path):
    path = _det_file(tmp_path / "det.txt")
    collect = RowCollector()
    run(make_tracker("boxtrack"), frames_from_table(read_mot(path)), collect)
    write_mot(tmp_path / "at_once.txt", collect.rows())
    with MotWriter(tmp_path / "streamed.txt") as writer:
        run(make_tracker("boxtrack"), DetectionStream(path, chunk_lines=7), writer)
    assert (tmp_path / "streamed.txt").read_bytes() == (tmp_path / "at_once.txt").read_bytes()


def test_writer_leaves_nothing_when_the_run_fails(tmp_path):
    target = tmp_path / "out.txt"
    target.write_text("old\n")

    class Failing:
        def update(self, frame):
            if frame.index == 3:
                raise ValueError("boom")
            return []

    with pytest.raises(ValueError, match="boom"), MotWriter(target) as writer:
        run(Failing(), (Frame(index=k, time=k, detections=Detections.empty()) for k in range(10)), writer)
    assert target.read_text() == "old\n"
    assert [p.name for p in tmp_path.iterdir()] == ["out.txt"]


def test_a_signal_before_the_writer_holds_its_file_leaves_no_temporary_file(tmp_path, monkeypatch):
    """SIGTERM (or Ctrl-C) between making the temporary file and entering the ``with`` block left it behind (seen
    under load: ``.out.x8anya5v.tmp.txt``). The file is now made on entering, and one interrupted while being made
    is removed."""
    import os

    from lookalike.io import rules

    target = tmp_path / "out.txt"
    target.write_text("old\n")
    writer = MotWriter(target)  # (a signal here, before the with block, has nothing to leave behind)
    assert [p.name for p in tmp_path.iterdir()] == ["out.txt"]
    with writer:
        writer.write_rows(np.array([[1, 1, 0, 0, 5, 5, 1, -1, -1, -1]], dtype=float))
    assert target.read_text().startswith("1,1,")

    def interrupted(fd, mode):
        raise KeyboardInterrupt

    monkeypatch.setattr(os, "fchmod", interrupted)
    with pytest.raises(KeyboardInterrupt):
        rules.temp_beside(target)
    assert [p.name for p in tmp_path.iterdir()] == ["out.txt"]
    monkeypatch.undo()
    unused = MotWriter(tmp_path / "empty.txt")  # closed without rows or a with block: an empty file all the same
    assert unused.close() == tmp_path / "empty.txt" and (tmp_path / "empty.txt").read_text() == ""
    with pytest.raises(ValueError, match="writer already closed"):
        unused.write_rows(np.zeros((1, 10)))


def test_track_cli_streams_the_same_file_as_the_old_loop(tmp_path):
    from lookalike.pipeline.results import add_confidence

    path = _det_file(tmp_path / "det.txt", frames=120)
    result = runner.invoke(app, ["track", "-t", "sort", str(path), "-o", str(tmp_path / "out.txt")])
    assert result.exit_code == 0, result.output
    tracker = make_tracker("sort")
    rows = [RowCollector()]
    run(tracker, frames_from_table(read_mot(path)), rows[0])
    write_mot(tmp_path / "ref.txt", rows[0].rows())
    add_confidence([(tmp_path / "ref.txt", 30.0)])  # track's last step: column 7 is the identity confidence
    assert (tmp_path / "out.txt").read_bytes() == (tmp_path / "ref.txt").read_bytes()


@pytest.mark.parametrize("name", ["deepsort", "diversort", "kalman_ha", "kalman_ha2", "jpda", "lstm"])
def test_trackers_that_cannot_run_on_boxes_say_what_they_need_in_one_line(tmp_path, name):
    path = _det_file(tmp_path / "det.txt", frames=5)
    result = runner.invoke(app, ["track", "-t", name, str(path), "-o", str(tmp_path / "out.txt")])
    assert result.exit_code == 2
    text = result.output.strip()
    assert len(text.splitlines()) == 1 and "Traceback" not in text
    assert name in text and ("appearance" in text if "sort" in name else "headings" in text)
    assert not (tmp_path / "out.txt").exists()


def test_box_input_problem_names_what_each_tracker_needs():
    from lookalike.io.needs import box_input_problem
    from lookalike.trackers import tracker_names

    assert box_input_problem("sort") is None and box_input_problem("boxtrack") is None
    assert box_input_problem("deepsort", video=True) is None  # a video gives it appearance features
    assert "--video" in (box_input_problem("diversort") or "")
    assert "headings" in (box_input_problem("kalman_ha", video=True) or "")
    for name in tracker_names():
        problem = box_input_problem(name)
        assert problem is None or (name in problem and "\n" not in problem)


def test_targets_makes_a_closed_set_or_is_refused(tmp_path):
    path = _det_file(tmp_path / "det.txt", frames=40)
    out = tmp_path / "closed.txt"
    result = runner.invoke(app, ["track", "-t", "boxtrack", "--targets", "2", str(path), "-o", str(out)])
    assert result.exit_code == 0, result.output
    ids = {int(line.split(",")[1]) for line in out.read_text().splitlines()}
    assert 0 < len(ids) <= 2
    refused = runner.invoke(app, ["track", "-t", "sort", "--targets", "2", str(path), "-o", str(tmp_path / "x.txt")])
    assert refused.exit_code == 2 and "--targets" in refused.output
