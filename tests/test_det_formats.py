"""Detection files in other layouts (a header line, x1,y1,x2,y2 corners, whitespace, 0-based frames) are read as the
MOTChallenge file they stand for, with a note of what was assumed; MOTChallenge files are read as before; values
that look wrong are warned about; ``eval --csv`` writes plain numbers."""

from __future__ import annotations

import csv
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from lookalike.cli import app
from lookalike.io import find_sequences, read_mot
from lookalike.io.det_format import DetFormat, parse_columns, read_det, sniff_det
from lookalike.io.stream import sequence_stream

runner = CliRunner()
DATA = Path(__file__).resolve().parents[2] / "shared" / "data"
MOT15 = DATA / "mot15"

# frame, left, top, width, height, score: two boxes a frame over 6 frames (the second box 0.1 px a frame slower)
_ROWS = np.array([[f, 50 + 5 * f, 60.5, 40.25, 80, 0.9 - 0.01 * f] for f in range(1, 7)]
                 + [[f, 300 + 4.9 * f, 100, 30, 60, 0.8] for f in range(1, 7)])
_ROWS = _ROWS[np.argsort(_ROWS[:, 0], kind="stable")]


def _mot_text(rows: np.ndarray = _ROWS) -> str:
    return "".join(f"{int(f)},-1,{x:g},{y:g},{w:g},{h:g},{s:g},-1,-1,-1\n" for f, x, y, w, h, s in rows)


def _xyxy_text(rows: np.ndarray = _ROWS, sep: str = ",") -> str:
    return "".join(sep.join(f"{v:g}" for v in (f, x, y, x + w, y + h, s, 0)) + "\n" for f, x, y, w, h, s in rows)


def _layouts() -> dict[str, tuple[str, str]]:
    """name → (file text, a word the note must hold)."""
    return {
        "xyxy header-less": (_xyxy_text(), "x1,y1,x2,y2"),
        "xyxy with a header": ("frame,x1,y1,x2,y2,score,class\n" + _xyxy_text(), "header line"),
        "MOT with a header": ("frame,id,bb_left,bb_top,bb_width,bb_height,conf,x,y,z\n" + _mot_text(), "header line"),
        "whitespace": (_mot_text().replace(",", " "), "whitespace"),
        "tabs and xyxy": (_xyxy_text(sep="\t"), "whitespace"),
        "0-based frames": (_mot_text(_ROWS - np.array([1, 0, 0, 0, 0, 0])), "0-based"),
        "quoted header (R)": ('"frame","id","bb_left","bb_top","bb_width","bb_height","conf","x","y","z"\n'
                               + _mot_text(), "header line"),
        # pandas' to_csv without index=False: an unnamed first column (was dropped, shifting every name one column)
        "an unnamed index column": (",frame,x1,y1,x2,y2,score,class\n" + "".join(
            f"{k},{line}" for k, line in enumerate(_xyxy_text().splitlines(keepends=True))), "-,frame,x1"),
    }


@pytest.mark.parametrize("name", list(_layouts()))
def test_other_layouts_read_as_the_motchallenge_file(name: str, tmp_path: Path) -> None:
    text, word = _layouts()[name]
    path = tmp_path / "det.txt"
    path.write_text(text)
    fmt, notes = sniff_det(path)
    assert not fmt.standard() and notes and word in " ".join(notes)
    table = read_det(path, fmt)
    np.testing.assert_array_equal(table.frame, _ROWS[:, 0])
    np.testing.assert_allclose(table.xywh, _ROWS[:, 1:5], atol=1e-9)
    np.testing.assert_allclose(table.conf, _ROWS[:, 5])
    assert (table.track_id == -1).all()


@pytest.mark.parametrize("name", list(_layouts()))
def test_track_gives_the_motchallenge_result_and_notes_it(name: str, tmp_path: Path) -> None:
    """``track`` on each layout writes the result of the MOTChallenge file, and prints a note."""
    (tmp_path / "mot.txt").write_text(_mot_text())
    (tmp_path / "other.txt").write_text(_layouts()[name][0])
    ref = runner.invoke(app, ["track", "-t", "boxtrack", str(tmp_path / "mot.txt"), "-o", str(tmp_path / "a.txt")])
    assert ref.exit_code == 0 and "note:" not in ref.output, ref.output
    got = runner.invoke(app, ["track", "-t", "boxtrack", str(tmp_path / "other.txt"), "-o", str(tmp_path / "b.txt")])
    assert got.exit_code == 0 and "note:" in got.output, got.output
    a, b = read_mot(tmp_path / "a.txt"), read_mot(tmp_path / "b.txt")
    assert len(a) > 0
    np.testing.assert_array_equal(a.frame, b.frame)
    np.testing.assert_array_equal(a.track_id, b.track_id)
    np.testing.assert_allclose(a.xywh, b.xywh, atol=2e-3)  # results are written to 3 decimals


def test_det_format_option_names_the_columns(tmp_path: Path) -> None:
    path = tmp_path / "det.txt"
    path.write_text(_xyxy_text())
    fmt, notes = sniff_det(path, "frame,x1,y1,x2,y2,score,class")
    assert fmt.corners and "--det-format" in notes[0]
    np.testing.assert_allclose(read_det(path, fmt).xywh, _ROWS[:, 1:5], atol=1e-9)
    zero = tmp_path / "zero.txt"
    zero.write_text("".join(f"{int(f) - 1} {x:g} {y:g} {w:g} {h:g}\n" for f, x, y, w, h, _ in _ROWS))
    fmt, _ = sniff_det(zero, "frame0 left top width height")
    table = read_det(zero, fmt)
    assert table.frame.min() == 1 and (table.conf == 1).all()
    assert parse_columns("frame,id,bb_left,bb_top,bb_width,bb_height,conf,x,y,z")[:7] == DetFormat(
        ("frame", "id", "left", "top", "width", "height", "score")).roles


@pytest.mark.parametrize(("text", "spec", "expected"), [
    ("1 2 3\n", "auto", "frame,id,left,top,width,height,score"),
    ("frame,a,b,c\n1,2,3,4\n", "auto", "frame,id,left,top,width,height,score"),
    ("1,-1,10,20\n", "auto", "frame,id,left,top,width,height,score"),
    ("1,-1,10,20,30,40\n", "frame,foo", "frame,id,left,top,width,height,score"),
    ("1,-1,10,x,30,40\n", "mot", "frame,id,left,top,width,height,score"),
    # a spreadsheet's export with ';' (and decimal commas): was a 'header line' naming no columns
    ("1;-1;10,5;20;30;40;0,9\n", "auto", "det.txt:1: columns separated by ';' (decimal commas?)"),
    ("frame;id;left;top;width;height\n1;-1;10;20;30;40\n", "auto", "det.txt:1: columns separated by ';'"),
])
def test_an_unreadable_file_is_refused_with_the_expected_columns(text: str, spec: str, expected: str,
                                                                 tmp_path: Path) -> None:
    path = tmp_path / "det.txt"
    path.write_text(text)
    result = runner.invoke(app, ["track", str(path), "-o", str(tmp_path / "o.txt"), "--det-format", spec])
    assert result.exit_code == 2 and expected in result.output and "Traceback" not in result.output, result.output
    assert len([ln for ln in result.output.splitlines() if ln.strip()]) == 1


def test_warnings_boxes_outside_equal_scores_and_no_tracks(tmp_path: Path) -> None:
    seq = tmp_path / "seq"
    (seq / "det").mkdir(parents=True)
    (seq / "seqinfo.ini").write_text("[Sequence]\nname=seq\nframeRate=25\nseqLength=6\nimWidth=200\nimHeight=100\n")
    # x1, y1, x2, y2 put in the width and height columns: boxes reach past the 200x100 frame
    rows = _ROWS.copy()
    rows[:, 3:5] += rows[:, 1:3]
    rows[:, 5] = 1.0
    (seq / "det" / "det.txt").write_text(_mot_text(rows))
    result = runner.invoke(app, ["track", "-t", "boxtrack", str(seq), "-o", str(tmp_path / "out")])
    assert result.exit_code == 0, result.output
    assert "centred outside the 200x100 frame" in result.output and "every score is 1" in result.output
    result = runner.invoke(app, ["track", "-t", "boxtrack", str(seq), "-o", str(tmp_path / "out2"),
                                 "--min-score", "2"])
    assert result.exit_code == 0 and "wrote no tracks from the 12 detections" in result.output, result.output


def test_normalised_coordinates_are_warned_about(tmp_path: Path) -> None:
    """Boxes in [0, 1] (normalised, as YOLO writes them) lie inside any frame: a warning says so; pixels warn not."""
    seq = tmp_path / "seq"
    (seq / "det").mkdir(parents=True)
    (seq / "seqinfo.ini").write_text("[Sequence]\nname=seq\nframeRate=25\nseqLength=6\nimWidth=640\nimHeight=480\n")
    for name, rows in (("pixels", _ROWS), ("normalised", _ROWS / np.array([1, 640, 480, 640, 480, 1]))):
        for det_format in ("auto", "frame,id,left,top,width,height,score"):  # streamed, and read whole
            (seq / "det" / "det.txt").write_text(_mot_text(rows))
            result = runner.invoke(app, ["track", "-t", "sort", str(seq), "-o", str(tmp_path / "out"),
                                         "--det-format", det_format])
            assert result.exit_code == 0, result.output
            warned = "no box is wider or higher than 1 px: are the coordinates normalised" in result.output
            assert warned == (name == "normalised"), result.output


@pytest.mark.skipif(not MOT15.is_dir(), reason="needs ../shared/data")
def test_motchallenge_files_are_streamed_as_before() -> None:
    """Standard files: no note, no warning, the streaming reader."""
    for seq in find_sequences(MOT15):
        assert seq.det_path is not None
        fmt, notes = sniff_det(seq.det_path)
        assert fmt.standard() and notes == []
        stream = sequence_stream(seq)
        assert stream.notes == [] and stream.outside == 0
        assert stream.scores is not None and stream.scores[0] < stream.scores[1]


@pytest.mark.skipif(not MOT15.is_dir(), reason="needs ../shared/data")
def test_eval_csv_holds_plain_numbers(tmp_path: Path) -> None:
    """Every cell after the tracker and sequence names reads back as a float."""
    seq = MOT15 / "TUD-Campus"
    res = tmp_path / "res"
    assert runner.invoke(app, ["track", "-t", "boxtrack", str(seq), "-o", str(res)]).exit_code == 0
    out = tmp_path / "scores.csv"
    result = runner.invoke(app, ["eval", "--gt", str(seq), "--results", str(res), "--csv", str(out)])
    assert result.exit_code == 0, result.output
    with open(out, newline="") as fh:
        header, *rows = list(csv.reader(fh))
    assert rows and all(len(row) == len(header) for row in rows)
    for row in rows:
        for key, cell in zip(header[2:], row[2:]):
            assert np.isfinite(float(cell)) or cell in ("nan", "inf", "-inf"), (key, cell)
