"""Issue 19, the input side: one test per row of the issue's table that concerns ``lookalike track``,
``make_tracker`` and ``--set``. Each bad input gets one line naming the file, line or field (exit 2),
nothing is written, and an existing output is kept; or the behaviour is correct."""

import os
import time
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from typer.testing import CliRunner

from lookalike.cli import app
from lookalike.io import MotWriter, read_mot, write_mot
from lookalike.trackers import make_tracker

runner = CliRunner()
ROW = "{f},-1,{x},10,20,40,0.9,-1,-1,-1\n"


def _det(path: Path, frames=range(1, 22), extra: str = "") -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text("".join(ROW.format(f=f, x=10 + f) for f in frames) + extra)
    return path


def _seq(root: Path, name: str | None = None, length: int | str | None = 21, rate: str = "30",
         frames=range(1, 22)) -> Path:
    info = ["[Sequence]", f"name={name or root.name}", f"frameRate={rate}"]
    if length is not None:
        info.append(f"seqLength={length}")
    root.mkdir(parents=True, exist_ok=True)
    (root / "seqinfo.ini").write_text("\n".join(info) + "\n")
    _det(root / "det" / "det.txt", frames)
    return root


def _track(*args: str):
    return runner.invoke(app, ["track", *map(str, args)])


def _one_error_line(r, *needles: str) -> str:
    assert r.exit_code == 2, r.output
    assert "Traceback" not in r.output
    lines = [line for line in r.output.splitlines() if line.strip()]
    assert len(lines) == 1 and lines[0].startswith("error:"), r.output
    for needle in needles:
        assert needle in lines[0], (needle, lines[0])
    return lines[0]


def test_output_equal_to_the_input_is_refused_and_the_input_kept(tmp_path):
    det = _det(tmp_path / "det.txt")
    before = det.read_text()
    _one_error_line(_track(det, "-o", det), "is the input")
    link = tmp_path / "link.txt"
    link.symlink_to(det)
    _one_error_line(_track(det, "-o", link), "is the input")
    _one_error_line(_track(tmp_path / "det.txt", "-o", tmp_path / "sub" / ".." / "det.txt"), "is the input")
    assert det.read_text() == before
    seq = _seq(tmp_path / "seqs" / "A")  # a folder of sequences whose output is one sequence's det folder
    (seq / "det" / "A.txt").symlink_to(seq / "det" / "det.txt")
    _one_error_line(_track(tmp_path / "seqs", "-o", seq / "det"), "is the input")
    assert (seq / "det" / "det.txt").read_text().count("\n") == 21


def test_two_sequences_with_one_name_are_refused_before_running(tmp_path):
    _seq(tmp_path / "all" / "first", name="same")
    _seq(tmp_path / "all" / "second", name="same")
    _one_error_line(_track(tmp_path / "all", "-o", tmp_path / "res"), "two sequences are named 'same'")
    assert not (tmp_path / "res").exists() or not list((tmp_path / "res").iterdir())
    _seq(tmp_path / "case" / "x", name="Seq")
    _seq(tmp_path / "case" / "y", name="seq")  # one file on a case-insensitive file system
    _one_error_line(_track(tmp_path / "case", "-o", tmp_path / "res2"), "two sequences")


@pytest.mark.parametrize("stray", ["1000000", "100000000"])
def test_one_stray_frame_number_fails_fast_naming_the_line(tmp_path, stray):
    det = _det(tmp_path / "det.txt", range(1, 21), extra=ROW.format(f=stray, x=1))
    start = time.perf_counter()
    _one_error_line(_track(det, "-o", tmp_path / "o.txt"), "det.txt:21", f"frame {stray}")
    assert time.perf_counter() - start < 30  # it used to run 294 s (1e6) or forever (1e8)
    assert not (tmp_path / "o.txt").exists()


def test_empty_det_is_a_warning_and_an_empty_result(tmp_path):
    det = tmp_path / "det.txt"
    det.write_text("")
    r = _track(det, "-o", tmp_path / "o.txt")
    assert r.exit_code == 0, r.output
    assert "warning" in r.output and "no detections" in r.output and "inf" not in r.output
    assert (tmp_path / "o.txt").read_text() == ""


@pytest.mark.parametrize("length", ["0", "-5", "ten", "2.5"])
def test_seqlength_must_be_a_positive_integer(tmp_path, length):
    seq = _seq(tmp_path / "S", length=length)
    _one_error_line(_track(seq, "-o", tmp_path / "res"), "seqinfo.ini", "seqLength", repr(length))
    assert not (tmp_path / "res").exists()


def test_frames_past_seqlength_are_an_error_unless_no_seqinfo_length(tmp_path):
    seq = _seq(tmp_path / "S", length=10, frames=range(1, 72))
    _one_error_line(_track(seq, "-o", tmp_path / "res"), "det.txt:11", "frame 11 > 10", "seqinfo.ini",
                    "--no-seqinfo-length")
    assert not (tmp_path / "res" / "S.txt").exists()
    r = _track(seq, "-o", tmp_path / "res", "--no-seqinfo-length", "--set", "min_hits=1")
    assert r.exit_code == 0, r.output
    assert read_mot(tmp_path / "res" / "S.txt").frame.max() == 71
    r = _track(seq, "-o", tmp_path / "res2", "--no-seqinfo-length", "--targets", "1", "--offline", "-t", "boxtrack")
    assert r.exit_code == 0, r.output
    r = _track(seq, "-o", tmp_path / "res3", "--targets", "1", "--offline", "-t", "boxtrack")
    _one_error_line(r, "det.txt:11", "seqLength")


@pytest.mark.parametrize("line, needle", [("2.7,-1,10,10,20,40,0.9", "frame 2.7 is not an integer"),
                                          ("3,-1,10,10,20,40,nan", "NaN or infinity"),
                                          ("3,-1,10,inf,20,40,0.9", "NaN or infinity"),
                                          ("0,-1,10,10,20,40,0.9", "frame 0 is not an integer >= 1"),
                                          ("3,-1,10,10,0,40,0.9", "zero or negative width or height"),
                                          ("3,-1,10,10,20,-4,0.9", "zero or negative width or height")])
def test_non_integer_frames_and_nan_scores_are_errors_naming_the_line(tmp_path, line, needle):
    det = _det(tmp_path / "det.txt", range(1, 3), extra=line + "\n")
    _one_error_line(_track(det, "-o", tmp_path / "o.txt"), "det.txt:3", needle)


@pytest.mark.parametrize("rate", ["0", "nan", "-25", "inf", "fast"])
def test_frame_rate_must_be_a_positive_number(tmp_path, rate):
    seq = _seq(tmp_path / "S", rate=rate)
    _one_error_line(_track(seq, "-o", tmp_path / "res"), "seqinfo.ini", "frameRate", repr(rate))


def test_a_binary_file_names_the_file(tmp_path):
    det = tmp_path / "det.txt"
    det.write_bytes(b"1,-1,1,1,1,1,1\n\xd0\xcf\x11\xe0\x00\x01binary")
    _one_error_line(_track(det, "-o", tmp_path / "o.txt"), str(det), "not UTF-8")
    seq = _seq(tmp_path / "S")
    (seq / "seqinfo.ini").write_bytes(b"[Sequence]\nname=\xff\xfe\n")
    _one_error_line(_track(seq, "-o", tmp_path / "res"), "seqinfo.ini", "not UTF-8")


def test_unwritable_outputs_are_one_line_errors_and_existing_files_kept(tmp_path):
    det = _det(tmp_path / "in" / "det.txt")
    blocker = tmp_path / "file.txt"
    blocker.write_text("keep me\n")
    _one_error_line(_track(det, "-o", blocker / "o.txt"), "file.txt")  # under a file
    folder = tmp_path / "existing"
    folder.mkdir()
    _one_error_line(_track(det, "-o", folder), "is a folder")  # -o an existing directory
    _seq(tmp_path / "seqs" / "A")
    _one_error_line(_track(tmp_path / "seqs", "-o", blocker), "is a file")  # a folder of sequences onto a file
    assert blocker.read_text() == "keep me\n"
    if os.geteuid() != 0:  # root may write anywhere
        locked = tmp_path / "locked"
        locked.mkdir()
        locked.chmod(0o500)
        try:
            _one_error_line(_track(det, "-o", locked / "o.txt"), "locked", "not writable")
        finally:
            locked.chmod(0o700)


def test_writer_keeps_the_existing_file_and_leaves_no_temp_on_error(tmp_path):
    out = tmp_path / "o.txt"
    out.write_text("old\n")
    with pytest.raises(RuntimeError), MotWriter(out) as writer:
        writer.write_rows(read_mot(_det(tmp_path / "d" / "det.txt")).frame[:0].reshape(0, 10))
        raise RuntimeError("stop")
    assert out.read_text() == "old\n" and sorted(os.listdir(tmp_path)) == ["d", "o.txt"]


@pytest.mark.parametrize("value", ["7", "nan", "-1"])
def test_set_out_of_range_is_refused(tmp_path, value):
    det = _det(tmp_path / "det.txt")
    _one_error_line(_track(det, "-o", tmp_path / "o.txt", "--set", f"iou_threshold={value}"),
                    "tracker 'sort': iou_threshold=")
    assert not (tmp_path / "o.txt").exists()


def test_make_tracker_with_a_string_is_a_clear_error():
    with pytest.raises(TypeError, match=r"tracker 'sort': max_age='3' must be an int"):
        make_tracker("sort", max_age="3")


@pytest.mark.parametrize("mask", [0o022, 0o077, 0o002])
def test_result_files_get_the_users_umask(tmp_path, mask):
    old = os.umask(mask)
    try:
        det = _det(tmp_path / "det.txt")
        r = _track(det, "-o", tmp_path / "o.txt")
        assert r.exit_code == 0, r.output
        written = write_mot(tmp_path / "w.txt", read_mot(tmp_path / "o.txt").frame[:0].reshape(0, 10))
    finally:
        os.umask(old)
    assert (tmp_path / "o.txt").stat().st_mode & 0o777 == 0o666 & ~mask
    assert written.stat().st_mode & 0o777 == 0o666 & ~mask


# Errors as plain text: quoted input that looks like rich markup is printed as given, never parsed.
_MARKUP = st.text(alphabet="[]/ab =#@\\", min_size=1, max_size=12) | st.sampled_from(
    ["[/]", "[bold red]", "[bold red]x[/]", "[link=x]", "\\[/]", "[/bold]", "[@click]"])


def _literal_error(r, text: str) -> None:
    line = _one_error_line(r)
    assert "MarkupError" not in r.output
    assert text in line or repr(text)[1:-1] in line, (text, line)


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(text=_MARKUP)
def test_markup_in_quoted_input_is_printed_literally(tmp_path, text):
    det = _det(tmp_path / "det.txt")
    _literal_error(_track(det, "-o", tmp_path / "o.txt", "-t", text), text)
    key = text.replace("=", "")
    if key.strip():
        _literal_error(_track(det, "-o", tmp_path / "o.txt", "--set", f"{key}=1"), key.strip())
    _literal_error(runner.invoke(app, ["serve", "--log-level", text]), text)
    _literal_error(runner.invoke(app, ["eval", "--gt", str(tmp_path), "--results", str(tmp_path), "--metrics",
                                       text.replace(",", "")]), text.replace(",", "").strip())
    bad = _det(tmp_path / "bad" / "det.txt", extra=f"22,{text},1,1,1,1,1,-1,-1,-1\n")
    r = _track(bad, "-o", tmp_path / "o.txt")
    _one_error_line(r, "det.txt")
    assert "MarkupError" not in r.output
    assert not (tmp_path / "o.txt").exists()
