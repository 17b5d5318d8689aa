"""Input files as real tools save them: a UTF-8 byte order mark (Windows editors, spreadsheets), UTF-16 with its
mark (PowerShell), compression (gzip, bzip2, xz, told by the content) and ``#`` comments are read as the plain text,
by every reader and by ``lookalike track`` and ``eval``."""

from __future__ import annotations

import bz2
import gzip
import lzma
from pathlib import Path

import numpy as np
from typer.testing import CliRunner

from lookalike.cli import app
from lookalike.io import read_mot, read_seqinfo
from lookalike.io.points import read_id_points, read_points_csv

runner = CliRunner()
BOM = b"\xef\xbb\xbf"
_DET = "".join(f"{f},-1,{50 + 5 * f},60,40,80,0.9,-1,-1,-1\n{f},-1,{300 + 4 * f},100,30,60,0.8,-1,-1,-1\n"
               for f in range(1, 7))


def test_a_byte_order_mark_is_not_part_of_the_first_value(tmp_path: Path) -> None:
    plain, marked = tmp_path / "plain.txt", tmp_path / "marked.txt"
    plain.write_text(_DET)
    marked.write_bytes(BOM + _DET.encode())
    a, b = read_mot(marked), read_mot(plain)
    np.testing.assert_array_equal(a.frame, b.frame)
    np.testing.assert_array_equal(a.xywh, b.xywh)

    points = tmp_path / "points.csv"  # no header: the first row is a point, not a header to skip
    points.write_bytes(BOM + b"1,5,10\n1,20,30\n2,6,11\n")
    assert read_points_csv(points).count == 3
    ids = tmp_path / "ids.csv"
    ids.write_bytes(BOM + b"1,1,5,10\n2,1,6,11\n")
    assert read_id_points(ids)[0].tolist() == [1, 2]

    info = tmp_path / "seqinfo.ini"
    info.write_bytes(BOM + b"[Sequence]\r\nname=S\r\nseqLength=6\r\n")
    assert read_seqinfo(info)["seqLength"] == "6"


def test_track_reads_a_marked_file_and_sequence_as_the_plain_one(tmp_path: Path) -> None:
    for name, mark in (("plain", b""), ("marked", BOM)):
        seq = tmp_path / name
        (seq / "det").mkdir(parents=True)
        (seq / "det" / "det.txt").write_bytes(mark + _DET.encode())
        (seq / "seqinfo.ini").write_bytes(mark + b"[Sequence]\nname=S\nframeRate=25\nseqLength=6\n")
        result = runner.invoke(app, ["track", "-t", "sort", str(seq), "-o", str(tmp_path / f"{name}-out")])
        assert result.exit_code == 0, result.output
    plain = (tmp_path / "plain-out" / "S.txt").read_text()
    assert plain and (tmp_path / "marked-out" / "S.txt").read_text() == plain


def test_gzip_compressed_files_are_read_as_their_text(tmp_path: Path) -> None:
    plain = tmp_path / "plain.txt"
    plain.write_text(_DET)
    results = {}
    for name in ("plain.txt", "det.txt.gz", "det.txt"):  # compressed under either name
        path = tmp_path / "in" / name
        path.parent.mkdir(exist_ok=True)
        path.write_bytes(_DET.encode() if name == "plain.txt" else gzip.compress(_DET.encode()))
        np.testing.assert_array_equal(read_mot(path).xywh, read_mot(plain).xywh)
        out = tmp_path / f"{name}.res"
        result = runner.invoke(app, ["track", "-t", "sort", str(path), "-o", str(out)])
        assert result.exit_code == 0, result.output
        results[name] = out.read_text()
    assert results["plain.txt"] and len(set(results.values())) == 1

    points = tmp_path / "points.csv.gz"  # its header names the columns: x and y are columns 3 and 4, not 2 and 3
    points.write_bytes(gzip.compress(b"frame,id,x,y\n1,1,5,10\n1,2,20,30\n2,1,6,11\n"))
    assert read_points_csv(points).points[0].tolist() == [[5, 10], [20, 30]]

    cut = tmp_path / "cut.txt.gz"
    cut.write_bytes(gzip.compress(_DET.encode())[:40])
    result = runner.invoke(app, ["track", "-t", "sort", str(cut), "-o", str(tmp_path / "cut.res")])
    assert result.exit_code == 2 and f"{cut}: a damaged or truncated gzip file" in result.output, result.output
    assert not (tmp_path / "cut.res").exists()


def test_eval_names_the_line_of_a_compressed_ground_truth(tmp_path: Path) -> None:
    seq = tmp_path / "S"
    (seq / "gt").mkdir(parents=True)
    (seq / "seqinfo.ini").write_text("[Sequence]\nname=S\nseqLength=6\n")
    gt = "".join(f"{f},{k},{50 + 100 * k},60,40,80,1,1,1\n" for f in range(1, 7) for k in (1, 2))
    (seq / "gt" / "gt.txt").write_bytes(gzip.compress((gt + gt.splitlines()[0] + "\n").encode()))
    (tmp_path / "res").mkdir()
    (tmp_path / "res" / "S.txt").write_text(gt)
    result = runner.invoke(app, ["eval", "--gt", str(seq), "--results", str(tmp_path / "res")])
    assert result.exit_code == 2, result.output
    assert "gt.txt:13: id 1 appears twice in frame 1" in result.output, result.output


def _commented(text: str) -> str:
    lines = text.splitlines(keepends=True)
    return "# written by my detector\n" + "".join(lines[:3]) + "  # a note\n" + "".join(lines[3:])


def test_comment_lines_are_skipped_and_errors_keep_their_line(tmp_path: Path) -> None:
    outputs = []
    for name, text in (("plain.txt", _DET), ("comma.txt", _commented(_DET)),
                       ("spaces.txt", _commented(_DET.replace(",", " ")))):
        path = tmp_path / name
        path.write_text(text)
        result = runner.invoke(app, ["track", "-t", "sort", str(path), "-o", str(tmp_path / f"{name}.res")])
        assert result.exit_code == 0, result.output
        outputs.append((tmp_path / f"{name}.res").read_text())
    assert outputs[0] and outputs[1] == outputs[0] and outputs[2] == outputs[0]

    bad = tmp_path / "bad.txt"  # line 7 (the 5th data line, after two comment lines) has a NaN score
    lines = _DET.splitlines(keepends=True)
    bad.write_text(_commented("".join(lines[:4] + [lines[4].replace(",0.9,", ",nan,")] + lines[5:])))
    for spec in ("auto", "frame,id,left,top,width,height,score"):
        result = runner.invoke(app, ["track", str(bad), "--det-format", spec, "-o", str(tmp_path / "bad.res")])
        assert result.exit_code == 2 and f"{bad}:7: NaN" in result.output, result.output


def test_a_comment_after_the_values_is_dropped_by_every_parser(tmp_path: Path) -> None:
    """numpy's fast reader dropped ``# ...`` after the values, the careful one (used when a line is wrong) did not: it
    blamed the comment's line instead of the wrong one."""
    det = tmp_path / "det.txt"
    det.write_text("1,-1,10,10,20,40,0.9  # the first box; a;b;c;d;e\n2,-1,10,10,20,40,0.9\n3,-1,10,10,20,40,nan\n")
    result = runner.invoke(app, ["track", str(det), "-o", str(tmp_path / "o.txt")])
    assert result.exit_code == 2 and f"{det}:3: NaN or infinity" in result.output, result.output
    points = tmp_path / "points.csv"
    points.write_text("frame,x,y\n1,5,10 # head\n2,6,11\n")
    assert read_points_csv(points).count == 2


def test_eval_names_the_line_past_comment_lines(tmp_path: Path) -> None:
    seq = tmp_path / "S"
    (seq / "gt").mkdir(parents=True)
    (seq / "seqinfo.ini").write_text("[Sequence]\nname=S\nseqLength=6\n")
    gt = "".join(f"{f},{k},{50 + 100 * k},60,40,80,1,1,1\n" for f in range(1, 7) for k in (1, 2))
    (seq / "gt" / "gt.txt").write_text(_commented(gt + gt.splitlines()[0] + "\n"))
    (tmp_path / "res").mkdir()
    (tmp_path / "res" / "S.txt").write_text(gt)
    result = runner.invoke(app, ["eval", "--gt", str(seq), "--results", str(tmp_path / "res")])
    assert result.exit_code == 2 and "gt.txt:15: id 1 appears twice in frame 1" in result.output, result.output


def test_compression_is_decided_by_the_content_not_the_name(tmp_path: Path) -> None:
    """A plain file named .gz or .bz2 is plain text (numpy chose a decompressor by the name: a traceback); bzip2 and
    xz files are read as gzip ones are, by ``read_mot`` and ``track`` alike."""
    plain = tmp_path / "plain.txt"
    plain.write_text(_DET)
    expected = read_mot(plain).xywh
    files = {"named.txt.gz": _DET.encode(), "named.txt.bz2": _DET.encode(), "packed.bz2": bz2.compress(_DET.encode()),
             "packed.txt.xz": lzma.compress(_DET.encode()), "packed.txt": lzma.compress(_DET.encode())}
    for name, data in files.items():
        path = tmp_path / name
        path.write_bytes(data)
        np.testing.assert_array_equal(read_mot(path).xywh, expected)
        result = runner.invoke(app, ["track", "-t", "sort", str(path), "-o", str(tmp_path / "out.txt")])
        assert result.exit_code == 0 and "note:" not in result.output, result.output
    cut = tmp_path / "cut.bz2"
    cut.write_bytes(bz2.compress(_DET.encode())[:60])
    result = runner.invoke(app, ["track", "-t", "sort", str(cut), "-o", str(tmp_path / "cut.res")])
    assert result.exit_code == 2 and f"{cut}: a damaged or truncated bzip2 file" in result.output, result.output


def test_utf16_text_as_powershell_writes_it(tmp_path: Path) -> None:
    """PowerShell's ``>`` writes UTF-16 with a byte order mark: read as its text (was 'not UTF-8 text (byte 0xff)');
    without the mark its NUL characters are named as such (were a 'header line' of '\\x001\\x00,...')."""
    plain, wide = tmp_path / "plain.txt", tmp_path / "wide.txt"
    plain.write_text(_DET)
    wide.write_bytes(_DET.encode("utf-16"))
    np.testing.assert_array_equal(read_mot(wide).xywh, read_mot(plain).xywh)
    outputs = []
    for path in (plain, wide):
        result = runner.invoke(app, ["track", "-t", "sort", str(path), "-o", str(tmp_path / f"{path.stem}.res")])
        assert result.exit_code == 0, result.output
        outputs.append((tmp_path / f"{path.stem}.res").read_text())
    assert outputs[0] and outputs[1] == outputs[0]
    bare = tmp_path / "bare.txt"
    bare.write_bytes(_DET.encode("utf-16-be"))
    result = runner.invoke(app, ["track", "-t", "sort", str(bare), "-o", str(tmp_path / "bare.res")])
    assert result.exit_code == 2 and f"{bare}:1: not UTF-8 text (a NUL character" in result.output, result.output
