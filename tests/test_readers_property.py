"""Property tests (hypothesis): every reader in lookalike.io, given arbitrary bytes or nearly valid text,
either parses cleanly or raises ``ValueError`` naming the file; never another exception, and
``lookalike track`` never leaves a partial result file behind."""

import os
from pathlib import Path

import numpy as np
import pytest

hypothesis = pytest.importorskip("hypothesis")
from hypothesis import HealthCheck, given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402
from typer.testing import CliRunner  # noqa: E402

from lookalike.cli import app  # noqa: E402
from lookalike.io import DetectionStream, find_sequences, read_mot, read_seqinfo  # noqa: E402
from lookalike.io.points import read_points_csv, read_points_mot  # noqa: E402
from lookalike.io.robot_sequences import read_robot_sequence  # noqa: E402

FAST = settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])

NUMBERS = st.sampled_from(["1", "2", "3", "-1", "0", "10.5", "2.7", "nan", "inf", "-inf", "1e308", "1e6", "1e8",
                           "", " ", "x", "0x10", "1_000", "-0", "99999999999999999999", "1e-320"])
ROW = st.lists(NUMBERS, min_size=0, max_size=11).map(",".join)
VALID_ROW = st.tuples(st.integers(1, 30), st.floats(0, 500), st.floats(0, 500), st.floats(1, 80), st.floats(1, 80),
                      st.floats(0, 1)).map(lambda r: f"{r[0]},-1," + ",".join(f"{v:.3f}" for v in r[1:]))
NEARLY_VALID = st.lists(st.one_of(VALID_ROW, VALID_ROW, ROW), max_size=25).map("\n".join).map(str.encode)
ANY_BYTES = st.binary(max_size=400)
INPUT = st.one_of(ANY_BYTES, NEARLY_VALID, st.text(max_size=300).map(lambda t: t.encode("utf-8", "surrogatepass")))


def _write(folder: Path, name: str, data: bytes) -> Path:
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / name
    path.write_bytes(data)
    return path


def _only_named_value_errors(call, path: Path):
    try:
        return call(path)
    except ValueError as exc:
        assert str(path) in str(exc), str(exc)
        assert "\n" not in str(exc).strip(), str(exc)
        return None


def _case(tmp_path: Path) -> Path:
    """A fresh folder per example (the tmp_path fixture is shared by hypothesis's examples)."""
    case = tmp_path / f"case{len(list(tmp_path.iterdir()))}"
    case.mkdir()
    return case


@FAST
@given(data=INPUT)
def test_read_mot_and_the_stream_agree_and_only_raise_named_value_errors(tmp_path, data):
    path = _write(_case(tmp_path), "det.txt", data)
    table = _only_named_value_errors(lambda p: read_mot(p, positive_size=True), path)  # as the stream (detections)
    stream = _only_named_value_errors(lambda p: DetectionStream(p, chunk_lines=4).check(), path)
    assert (table is None) == (stream is None)
    if table is not None and len(table):
        assert np.isfinite(table.xywh).all() and np.isfinite(table.conf).all()
        assert (table.frame >= 1).all() and (table.frame == np.floor(table.frame)).all()
        assert sum(len(f.detections) for f in stream) == len(table)


@FAST
@given(data=INPUT)
def test_seqinfo_only_raises_named_value_errors(tmp_path, data):
    folder = _case(tmp_path) / "seq"
    info = _write(folder, "seqinfo.ini", b"[Sequence]\n" + data if data[:1] != b"[" else data)
    _only_named_value_errors(read_seqinfo, info)
    _write(folder / "det", "det.txt", b"1,-1,1,1,5,5,0.9\n")
    found = _only_named_value_errors(lambda p: find_sequences(p.parent), info)
    if found:
        seq = found[0]
        assert seq.frame_rate > 0 and np.isfinite(seq.frame_rate)
        assert seq.length is None or seq.length >= 1
        assert "/" not in seq.name and seq.name not in ("", ".", "..")


@FAST
@given(data=INPUT)
def test_point_readers_only_raise_named_value_errors(tmp_path, data):
    path = _write(_case(tmp_path), "points.csv", data)
    for read in (read_points_csv, read_points_mot, lambda p: read_points_mot(p, centre=True)):
        points = _only_named_value_errors(read, path)
        if points is not None:
            assert len(points) <= 10_000 + 10 * 30  # no stray frame number blows the sequence up


HEADER = (b'{"format": "lookalike-robots", "version": 1, "seed": 1, "n_frames": 1, "reports_sent": 0, '
          b'"config": {}}\n')
FRAME = (b'{"frame": 0, "time": 0.0, "detections": {"position": [[1.0, 2.0]], "heading": [0.1], "score": [0.9], '
         b'"label": [0]}, "beacons": {"agent_id": [], "t_sent": [], "t_received": [], "heading": []}, "truth": '
         b'{"position": [[1, 2], [3, 4], [5, 6]], "heading": [0, 0, 0], "visible": [1, 1, 1], "occlusion": [0, 0, 0], '
         b'"field_position": [[1, 2], [3, 4], [5, 6]], "observer": [0, 0, 0], "n_false_positives": 0, '
         b'"n_misses": 0}}\n')


def _mutate(data: bytes, cut: int, insert: bytes) -> bytes:
    cut = cut % (len(data) + 1)
    return data[:cut] + insert + data[cut + len(insert):]


@FAST
@given(data=st.one_of(ANY_BYTES, st.tuples(st.integers(0, 2000), st.sampled_from(
    [b"NaN", b"1e999", b"-1", b"[]", b"{}", b'"x"', b"null", b"9223372036854775808", b"\xff\xfe", b"\n", b","])).map(
        lambda m: _mutate(HEADER + FRAME, *m))))
def test_robot_sequence_reader_only_raises_named_value_errors(tmp_path, data):
    path = _write(_case(tmp_path), "seq.jsonl", data)
    _only_named_value_errors(read_robot_sequence, path)


def test_the_robot_fixture_is_valid(tmp_path):
    seq = read_robot_sequence(_write(tmp_path, "seq.jsonl", HEADER + FRAME))
    assert len(seq.arrays) == 1


runner = CliRunner()


@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(data=INPUT)
def test_track_leaves_either_a_whole_result_or_nothing(tmp_path, data):
    case = _case(tmp_path)
    det = _write(case, "det.txt", data)
    out = case / "out" / "tracks.txt"
    out.parent.mkdir()
    out.write_text("previous result\n")
    r = runner.invoke(app, ["track", str(det), "-o", str(out)])
    assert r.exit_code in (0, 2), r.output
    assert r.exception is None or isinstance(r.exception, SystemExit), repr(r.exception)
    assert os.listdir(out.parent) == ["tracks.txt"]  # no temporary file left
    if r.exit_code == 2:
        assert out.read_text() == "previous result\n"  # an existing output is kept on error
    else:
        read_mot(out)
