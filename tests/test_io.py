from pathlib import Path

import numpy as np
import pytest

from lookalike.io import find_sequences, frames_from_table, read_mot, read_seqinfo, tracks_to_rows, write_mot
from lookalike.types import TrackSnapshot, TrackStatus


def _write(path: Path, text: str) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(text)
    return path


def test_read_detection_file(tmp_path):
    p = _write(tmp_path / "det.txt", "1,-1,10,20,30,40,0.9,-1,-1,-1\n\n3,-1,1,2,3,4,0.5,-1,-1,-1\n")
    t = read_mot(p)
    assert t.frame.tolist() == [1, 3]
    assert t.xywh.tolist() == [[10, 20, 30, 40], [1, 2, 3, 4]]
    frames = list(frames_from_table(t, length=4, frame_rate=10))
    assert [len(f.detections) for f in frames] == [1, 0, 1, 0]
    assert frames[2].index == 2 and frames[2].time == pytest.approx(0.2)
    assert len(list(frames_from_table(t, min_score=0.6))[2].detections) == 0


@pytest.mark.parametrize("kwargs, message", [
    ({"frame_rate": float("nan")}, "frame_rate must be a finite number above 0"),
    ({"frame_rate": float("inf")}, "frame_rate must be a finite number above 0"),  # every frame was at time 0
    ({"frame_rate": 0.0}, "frame_rate"),
    ({"length": 2.5}, "length must be a whole number"),  # a TypeError from range()
    ({"length": -2}, "length must be a whole number"),  # no frames, silently
    ({"min_score": float("nan")}, "min_score"),  # every detection dropped, silently
])
def test_frames_from_table_refuses_bad_arguments(tmp_path, kwargs, message):
    t = read_mot(_write(tmp_path / "det.txt", "1,-1,10,20,30,40,0.9,-1,-1,-1\n"))
    with pytest.raises(ValueError, match=message):
        list(frames_from_table(t, **kwargs))
    assert len(list(frames_from_table(t, length=np.int64(2), frame_rate=25))) == 2


def test_read_gt_with_class_and_visibility(tmp_path):
    p = _write(tmp_path / "gt.txt", "1,1,10,20,30,40,1,1,0.8\n1,2,0,0,5,5,0,7,1.0\n")
    t = read_mot(p)
    assert t.conf.tolist() == [1, 0]
    assert t.extra.tolist() == [[1, 0.8], [7, 1.0]]


@pytest.mark.parametrize(
    "text, message",
    [
        ("1,-1,10,20,30,40,0.9\n1,-1,10,20\n", ":2: expected at least 6"),
        ("1,-1,10,20,30,40,0.9\n2,-1,10,x,30,40,0.9\n", ":2: column 4 is not a number \\('x'\\)"),
        ("1,-1,10,20,30,40,0.9\n2,-1,10,,30,40,0.9\n", ":2: column 4 is empty"),
        ("1,-1,10,20,30,40,0.9\n\n2,-1,10,nan,30,40,0.9\n", ":3: NaN or infinity"),
        ("1,-1,10,20,-30,40,0.9\n", ":1: invalid box"),
        ("0,-1,10,20,30,40,0.9\n", ":1: invalid frame"),
        ("1,-1,10,20,30,40,0.9\n2.7,-1,10,20,30,40,0.9\n", ":2: invalid frame: frame 2.7 is not an integer"),
        ("1,-1,10,20,30,40,nan\n", ":1: NaN or infinity"),
        ("1,-1,10,20,30,40,0.9\n99999,-1,10,20,30,40,0.9\n", ":2: invalid frame: frame 99999 jumps"),
        # ids past 2^53 read as floats: 1e17+1 and 1e17+2 became one id, 1e20 the int64 minimum
        ("1,9007199254740992,1,2,3,4,1\n1,100000000000000001,1,2,3,4,1\n", ":2: invalid id: beyond"),
        ("1,-1e20,10,20,30,40,0.9\n", ":1: invalid id: beyond"),
    ],
)
def test_malformed_lines_name_file_and_line(tmp_path, text, message):
    p = _write(tmp_path / "bad.txt", text)
    with pytest.raises(ValueError, match=f"bad.txt{message}"):
        read_mot(p)


def test_a_trailing_comma_or_empty_xyz_columns_are_absent_columns(tmp_path):
    """Exporters write ``...,0.9,`` or leave x, y, z empty: read as the row without them (was 'not a number')."""
    plain = read_mot(_write(tmp_path / "plain.txt", "1,-1,10,20,30,40,0.9\n2,3,11,21,31,41,0.8\n"))
    for text in ("1,-1,10,20,30,40,0.9,\n2,3,11,21,31,41,0.8,\n", "1,-1,10,20,30,40,0.9,,,\n2,3,11,21,31,41,0.8,,,\n"):
        table = read_mot(_write(tmp_path / "comma.txt", text))
        np.testing.assert_array_equal(table.frame, plain.frame)
        np.testing.assert_array_equal(table.track_id, plain.track_id)
        np.testing.assert_array_equal(table.xywh, plain.xywh)
        np.testing.assert_array_equal(table.conf, plain.conf)


def test_min_columns_below_a_box_is_refused(tmp_path):
    p = _write(tmp_path / "three.txt", "1,2,3\n2,2,3\n")  # was numpy's 'zero-size array to reduction operation'
    with pytest.raises(ValueError, match="min_columns must be a whole number >= 6"):
        read_mot(p, min_columns=2)


def test_missing_file(tmp_path):
    with pytest.raises(FileNotFoundError, match="nope.txt"):
        read_mot(tmp_path / "nope.txt")


def test_empty_file_is_empty_table(tmp_path):
    assert len(read_mot(_write(tmp_path / "e.txt", ""))) == 0


def test_write_round_trip_and_atomicity(tmp_path):
    snaps = [TrackSnapshot(track_id=3, status=TrackStatus.CONFIRMED, xywh=np.array([1.5, 2, 3, 4]))]
    rows = [tracks_to_rows(0, snaps), tracks_to_rows(4, snaps)]
    out = write_mot(tmp_path / "res" / "seq.txt", rows)
    t = read_mot(out)
    assert t.frame.tolist() == [1, 5] and t.track_id.tolist() == [3, 3]
    np.testing.assert_allclose(t.xywh[0], [1.5, 2, 3, 4])

    def broken():
        yield tracks_to_rows(0, snaps)
        raise RuntimeError("tracker crashed")

    with pytest.raises(RuntimeError):
        write_mot(out, broken())
    assert read_mot(out).frame.tolist() == [1, 5]  # the earlier file is intact
    assert [p.name for p in out.parent.iterdir()] == ["seq.txt"]  # no temporary left behind


def test_a_link_is_written_through_and_a_named_pipe_is_written_into(tmp_path):
    """A result written to a symbolic link lands in the file it points at (the link stays); one written to a named
    pipe reaches its reader, and the pipe stays a pipe (renaming a finished file onto it would replace it, as it
    would replace ``/dev/null``)."""
    import os
    import stat
    import threading

    from lookalike.io.outputs import write_atomic

    snaps = [TrackSnapshot(track_id=3, status=TrackStatus.CONFIRMED, xywh=np.array([1.5, 2, 3, 4]))]
    real = tmp_path / "real.txt"
    real.write_text("old\n")
    link = tmp_path / "link.txt"
    link.symlink_to(real.name)
    write_mot(link, [tracks_to_rows(0, snaps)])
    assert link.is_symlink() and read_mot(real).track_id.tolist() == [3]
    write_atomic(link, "text\n")
    assert link.is_symlink() and real.read_text() == "text\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["link.txt", "real.txt"]

    pipe = tmp_path / "pipe"
    os.mkfifo(pipe)
    for write, lines in ((lambda: write_mot(pipe, [tracks_to_rows(0, snaps), tracks_to_rows(1, snaps)]), 2),
                         (lambda: write_atomic(pipe, "text\n"), 1)):
        got: list[bytes] = []
        reader = threading.Thread(target=lambda out=got: out.append(pipe.read_bytes()))
        reader.start()
        write()
        reader.join(timeout=30)
        assert got and got[0].count(b"\n") == lines and stat.S_ISFIFO(os.stat(pipe).st_mode)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["link.txt", "pipe", "real.txt"]


def _make_sequence(root: Path, name: str, length: int = 5) -> Path:
    seq = root / name
    _write(seq / "seqinfo.ini", f"[Sequence]\nname={name}\nframeRate=10\nseqLength={length}\nimWidth=64\nimHeight=48\n")
    _write(seq / "det" / "det.txt", "1,-1,1,1,5,5,1\n")
    _write(seq / "gt" / "gt.txt", "1,1,1,1,5,5,1\n")
    return seq


def test_find_sequences_in_all_three_forms(tmp_path):
    a = _make_sequence(tmp_path, "A")
    _make_sequence(tmp_path, "B")
    (tmp_path / "notes").mkdir()
    both = find_sequences(tmp_path)
    assert [s.name for s in both] == ["A", "B"]
    one = find_sequences(a)[0]
    assert one.frame_rate == 10 and one.length == 5 and one.image_size == (64, 48)
    assert one.gt_path == a / "gt" / "gt.txt"
    from_file = find_sequences(a / "det" / "det.txt")[0]
    assert from_file.name == "A" and from_file.length == 5
    bare = find_sequences(_write(tmp_path / "x" / "mydets.txt", "1,-1,1,1,5,5,1\n"))[0]
    assert bare.name == "mydets" and bare.length is None


def test_find_sequences_errors(tmp_path):
    with pytest.raises(FileNotFoundError):
        find_sequences(tmp_path / "missing")
    (tmp_path / "empty").mkdir()
    with pytest.raises(ValueError, match="neither a sequence folder"):
        find_sequences(tmp_path / "empty")
    _write(tmp_path / "s" / "seqinfo.ini", "[Sequence]\nframeRate=fast\n")
    with pytest.raises(ValueError, match="seqinfo.ini"):
        find_sequences(tmp_path / "s")
    with pytest.raises(ValueError, match="no \\[Sequence\\]"):
        read_seqinfo(_write(tmp_path / "bad.ini", "[Other]\na=1\n"))


def test_real_sequences_load(shared_data):
    seqs = find_sequences(shared_data / "mot15")
    assert len(seqs) == 7
    for s in seqs:
        t = read_mot(s.det_path)
        assert len(t) > 0 and t.frame.max() <= s.length


def test_fast_and_careful_parsers_agree(tmp_path):
    from lookalike.io.motchallenge import _parse_slowly

    p = _write(tmp_path / "a.txt", "1,2,3.5,4,5,6,0.9,1,0.5\n\n2,3,1,1,2,2,1,7,1\n")
    fast = read_mot(p)
    rows = [(i + 1, ln) for i, ln in enumerate(p.read_text().splitlines()) if ln.strip()]
    np.testing.assert_array_equal(fast.xywh, _parse_slowly(p, rows, 6)[:, 2:6])
    np.testing.assert_array_equal(fast.extra, [[1, 0.5], [7, 1]])


def test_detection_stream_and_evaluate_data_name_their_bad_arguments(tmp_path: Path) -> None:
    from lookalike.eval import evaluate_data, prepare_boxes
    from lookalike.io import DetectionStream, MotTable

    with pytest.raises(ValueError, match="length must be a whole number of frames >= 0, got 2.5"):
        DetectionStream(tmp_path / "det.txt", length=2.5)
    table = MotTable.from_rows(np.array([[1, -1, 0, 0, 5, 5, 1, -1, -1, -1]], float))
    with pytest.raises(ValueError, match="needs the file a table was read from"):
        DetectionStream.from_table(table)
    data = prepare_boxes(table, table)
    with pytest.raises(ValueError, match=r"^threshold must be in \(0, 1\]"):
        evaluate_data(data, threshold=0.0)
