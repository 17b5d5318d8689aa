"""Issue 19, the input side: one test per row of the issue's table that concerns ``lookalike track``,
``make_tracker`` and ``--set``. Each bad input gets one line naming the file, line or field (exit 2),
nothing is written, and an existing output is kept; or the behaviour is correct."""

import os
import subprocess
import sys
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
    # the offline closed set reads the file its own way: the same rules (a zero-size box was taken silently)
    offline = _track(det, "-o", tmp_path / "o.txt", "-t", "boxtrack", "--targets", "1", "--offline")
    _one_error_line(offline, "det.txt:3", needle)


@pytest.mark.parametrize("rate", ["0", "nan", "-25", "inf", "fast"])
def test_frame_rate_must_be_a_positive_number(tmp_path, rate):
    seq = _seq(tmp_path / "S", rate=rate)
    _one_error_line(_track(seq, "-o", tmp_path / "res"), "seqinfo.ini", "frameRate", repr(rate))


def test_a_binary_file_names_the_file(tmp_path):
    det = tmp_path / "det.txt"
    det.write_bytes(b"1,-1,1,1,1,1,1\n\xd0\xcf\x11\xe0\x00\x01binary")
    _one_error_line(_track(det, "-o", tmp_path / "o.txt"), str(det), "not UTF-8")
    video = tmp_path / "clip.mp4"  # binary from the first line: was sniffed as a 'header line' and printed raw
    video.write_bytes(b"\x00\x00\x00 ftypisom\x00\x00\x02\x00isomiso2avc1mp41\x00\x08free\xae\xff\x10\n\x01\x02")
    _one_error_line(_track(video, "-o", tmp_path / "o.txt"), f"{video}:1: not UTF-8")
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


# One output rule for every command: outputs decided and checked before any work, never onto an input, never two
# outputs on one file; every file written through a temporary file renamed into place.
GT_ROW = "{f},{i},{x},10,20,40,1,1,1\n"


def _gt_folder(root: Path) -> tuple[Path, Path]:
    """A ground-truth root with one sequence and a results folder for it; returns (gt root, results folder)."""
    seq = _seq(root / "gt" / "S1", length=21)
    (seq / "gt").mkdir()
    (seq / "gt" / "gt.txt").write_text("".join(GT_ROW.format(f=f, i=1, x=10 + f) for f in range(1, 22)))
    res = root / "res"
    res.mkdir()
    (res / "S1.txt").write_text("".join(ROW.format(f=f, x=10 + f).replace(",-1,", ",1,", 1) for f in range(1, 22)))
    return root / "gt", res


def _eval(gt: Path, res: Path, *extra):
    return runner.invoke(app, ["eval", "--gt", str(gt), "--results", str(res), "--metrics", "CLEAR", *map(str, extra)])


def test_eval_benchmark_names_any_case_and_refuses_others_before_scoring(tmp_path):
    gt, res = _gt_folder(tmp_path)
    ok = _eval(gt, res, "--benchmark", "mot17")
    assert ok.exit_code == 0, ok.output
    assert "(MOT17)" in ok.output
    r = _eval(gt, tmp_path / "missing", "--benchmark", "mot18")
    assert r.exit_code != 0
    assert "--benchmark: unknown benchmark 'mot18'; known: MOT15, MOT16, MOT17, MOT20, custom" in r.output


def _snapshot(*paths: Path) -> dict[Path, bytes]:
    return {p: p.read_bytes() for root in paths for p in ([root] if root.is_file() else sorted(root.rglob("*")))
            if p.is_file()}


def test_eval_outputs_onto_its_inputs_are_refused_before_scoring(tmp_path):
    gt, res = _gt_folder(tmp_path)
    before = _snapshot(tmp_path)
    gt_txt, seqinfo, result = gt / "S1" / "gt" / "gt.txt", gt / "S1" / "seqinfo.ini", res / "S1.txt"
    hard = tmp_path / "hard.txt"
    os.link(gt_txt, hard)
    soft = tmp_path / "soft.txt"
    soft.symlink_to(result)
    for option in ("--json", "--csv"):
        for target in (gt_txt, seqinfo, result, hard, soft):
            line = _one_error_line(_eval(gt, res, option, target), option)
            assert "MOTA" not in line
    _one_error_line(_eval(gt, res, "--json", tmp_path / "x", "--csv", tmp_path / "x"), "--json", "--csv", "one file")
    _one_error_line(_eval(gt, res, "--json", tmp_path / "x", "--csv", tmp_path / "sub" / ".." / "x"), "one file")
    assert _snapshot(gt, res) == {p: b for p, b in before.items() if p != hard}
    assert not (tmp_path / "x").exists()
    r = _eval(gt, res, "--json", tmp_path / "e.json", "--csv", tmp_path / "e.csv")
    assert r.exit_code == 0, r.output
    assert sorted(p.name for p in tmp_path.iterdir()) == ["e.csv", "e.json", "gt", "hard.txt", "res", "soft.txt"]


def test_report_tune_and_bench_ident_refuse_their_inputs(tmp_path):
    gt, res = _gt_folder(tmp_path)
    doc = tmp_path / "e.json"
    assert _eval(gt, res, "--json", doc).exit_code == 0
    before = doc.read_bytes()
    _one_error_line(runner.invoke(app, ["report", str(doc), "-o", str(doc)]), "-o/--output", "is the input")
    assert doc.read_bytes() == before
    gt_txt = gt / "S1" / "gt" / "gt.txt"
    text = gt_txt.read_text()
    _one_error_line(runner.invoke(app, ["tune", str(gt / "S1"), "-o", str(gt_txt), "--trials", "1"]), "is the input")
    assert gt_txt.read_text() == text
    recordings = tmp_path / "rec"
    recordings.mkdir()
    (recordings / "a.jsonl").write_text("recording\n")
    for option in ("--json", "--csv"):
        r = runner.invoke(app, ["bench", "ident", "--recordings", str(recordings), option,
                                str(recordings / "a.jsonl")])
        _one_error_line(r, option, "input folder")
    assert (recordings / "a.jsonl").read_text() == "recording\n"
    r = runner.invoke(app, ["bench", "ident", "--json", str(tmp_path / "t"), "--csv", str(tmp_path / "t")])
    _one_error_line(r, "one file")


@pytest.mark.parametrize("command", [["simulate", "--frames", "2"], ["train", "--steps", "1"],
                                     ["train-appearance"], ["record-pixels"]])
def test_folder_outputs_onto_an_existing_file_are_refused(tmp_path, command):
    existing = tmp_path / "model.npz"
    existing.write_text("keep\n")
    r = runner.invoke(app, [*command, "-o", str(existing)])
    _one_error_line(r, str(existing), "is a file")
    assert existing.read_text() == "keep\n"


def test_serve_port_file_in_a_missing_folder_is_created(tmp_path):
    port_file = tmp_path / "new" / "deeper" / "port.txt"
    r = runner.invoke(app, ["serve", "--duration", "0.1", "--port-file", str(port_file)])
    assert r.exit_code == 0, r.output
    assert port_file.read_text().startswith("127.0.0.1:")
    assert os.listdir(port_file.parent) == ["port.txt"]
    blocker = tmp_path / "file"
    blocker.write_text("")
    _one_error_line(runner.invoke(app, ["serve", "--duration", "0.1", "--port-file", str(blocker / "p.txt")]),
                    "is a file")


@pytest.fixture(scope="module")
def tiny_video(tmp_path_factory):
    """A 12-frame MP4 of a moving square and its det.txt."""
    import numpy as np

    from lookalike.viz.video import VideoWriter

    root = tmp_path_factory.mktemp("video")
    rows = []
    with VideoWriter(root / "in.mp4", fps=10) as writer:
        for k in range(12):
            image = np.zeros((64, 96, 3), np.uint8)
            image[20:40, 10 + 4 * k:30 + 4 * k] = 255
            writer.write(image)
            rows.append(f"{k + 1},-1,{10 + 4 * k},20,20,20,0.9,-1,-1,-1\n")
    (root / "det.txt").write_text("".join(rows))
    return root / "in.mp4", root / "det.txt"


def test_annotate_onto_an_input_or_another_output_is_refused_before_running(tiny_video, tmp_path):
    video, det = tiny_video
    before = _snapshot(video, det)
    link = tmp_path / "link.mp4"
    link.symlink_to(video)
    hard = tmp_path / "hard.mp4"
    os.link(video, hard)
    out = tmp_path / "o.txt"
    for target in (video, link, hard, det):
        _one_error_line(_track("--video", video, "--detections", det, "-o", out, "--annotate", target),
                        "--annotate", "is the input")
    _one_error_line(_track("--video", video, "--detections", det, "-o", out, "--annotate", out), "one file")
    _one_error_line(_track("--video", video, "--detections", det, "-o", out, "--annotate",
                           tmp_path / "o.health.csv"), "one file")
    assert _snapshot(video, det) == before and not out.exists()


def test_annotate_is_written_through_a_temporary_file(tiny_video, tmp_path):
    video, det = tiny_video
    old = tmp_path / "a.mp4"
    old.write_text("old video\n")
    r = _track("--video", video, "--detections", det, "-o", tmp_path / "o.txt", "--annotate", old)
    assert r.exit_code == 0, r.output
    assert old.read_bytes() != b"old video\n" and old.stat().st_size > 100
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.mp4", "o.health.csv", "o.txt"]


def test_sigterm_leaves_no_temporary_file(tmp_path):
    import signal

    det = tmp_path / "det.txt"
    with det.open("w") as fh:  # long enough to be mid-way when the signal comes
        for f in range(1, 60_001):
            fh.write("".join(f"{f},-1,{10 + 30 * i + f % 7},{20 + f % 5},20,40,0.9,-1,-1,-1\n" for i in range(6)))
    out = tmp_path / "res" / "o.txt"
    out.parent.mkdir()
    out.write_text("previous result\n")
    proc = subprocess.Popen([sys.executable, "-m", "lookalike", "track", str(det), "-o", str(out)],
                            stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, env={**os.environ, "COLUMNS": "200"})
    try:
        deadline = time.monotonic() + 60
        while len(os.listdir(out.parent)) < 2 and proc.poll() is None and time.monotonic() < deadline:
            time.sleep(0.02)
        assert proc.poll() is None, "the run ended before the signal"
        proc.send_signal(signal.SIGTERM)
        _, err = proc.communicate(timeout=30)
    finally:
        proc.kill()
    assert proc.returncode == 128 + signal.SIGTERM, err
    assert b"Traceback" not in err
    assert os.listdir(out.parent) == ["o.txt"] and out.read_text() == "previous result\n"


_TARGETS = st.sampled_from(["det", "gt", "seqinfo", "result", "json_in", "link_det", "hard_gt", "new_a", "new_b",
                            "gt_folder", "res_folder"])


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(command=st.sampled_from(["track", "eval", "report", "tune"]), first=_TARGETS, second=_TARGETS)
def test_no_combination_of_output_paths_modifies_an_input(tmp_path, command, first, second):
    import tempfile

    root = Path(tempfile.mkdtemp(dir=tmp_path))
    gt, res = _gt_folder(root)
    det = gt / "S1" / "det" / "det.txt"
    json_in = root / "in.json"
    assert _eval(gt, res, "--json", json_in).exit_code == 0
    (root / "link_det").symlink_to(det)
    os.link(gt / "S1" / "gt" / "gt.txt", root / "hard_gt")
    paths = {"det": det, "gt": gt / "S1" / "gt" / "gt.txt", "seqinfo": gt / "S1" / "seqinfo.ini",
             "result": res / "S1.txt", "json_in": json_in, "link_det": root / "link_det", "hard_gt": root / "hard_gt",
             "new_a": root / "new_a", "new_b": root / "new_b", "gt_folder": gt, "res_folder": res}
    read = {"track": [det, paths["seqinfo"]], "eval": [gt, res], "report": [json_in], "tune": [gt]}[command]
    inputs = _snapshot(*read)  # (the files the command reads)
    a, b = paths[first], paths[second]
    if command == "track":
        r = _track(det, "-o", a)
    elif command == "eval":
        r = _eval(gt, res, "--json", a, "--csv", b)
    elif command == "report":
        r = runner.invoke(app, ["report", str(json_in), "-o", str(a)])
    else:  # two outputs: the parameter file and the study's database
        r = runner.invoke(app, ["tune", str(gt / "S1"), "-t", "sort", "--trials", "1", "-o", str(a),
                                "--study", f"sqlite:///{b}"])
    assert "Traceback" not in r.output
    assert _snapshot(*read) == inputs, r.output
    if r.exit_code != 0:
        _one_error_line(r)


# Options that would make the output meaningless: one line, exit 2, before any work.
@pytest.mark.parametrize("args, needles", [
    (["bench", "shuffle", "--trackers", "nosuch"], ["--trackers", "'nosuch'"]),
    (["bench", "shuffle", "--setups", "nosuch"], ["--setups", "'nosuch'"]),
    (["bench", "recovery", "--trackers", "nosuch"], ["--trackers", "'nosuch'"]),
    (["bench", "recovery", "--trackers", "boxtrack"], ["--trackers", "unknown identifier 'boxtrack'"]),
    (["bench", "ident", "--trackers", "sort", "--sequences", "1", "--frames", "5"], ["unknown identifier 'sort'"]),
    (["bench", "recovery", "--swap-at-s", "100"], ["--swap-at-s 100", "end before the sequences do"]),
    (["bench", "recovery", "--swap-s", "-1"], ["--swap-s -1"]),
    (["bench", "recovery", "--swap-at-s", "-2"], ["--swap-at-s -2"]),
    (["bench", "ident", "--setups", ","], ["--setups: no team given"]),
    (["bench", "ident", "--setups", "m3n2", "--trackers", ","], ["--trackers: no identifier given"]),
    (["bench", "shuffle", "--setups", " , "], ["--setups: no team given"]),
    (["bench", "recovery", "--trackers", ","], ["--trackers: no identifier given"]),
    (["bench", "real", "--trackers", ",", "--peers", "none"], ["nothing to run", "--trackers"]),
    (["bench", "ident", "--lengths", ",", "--setups", "m3n2", "--trackers", "kalman_ha", "--sequences", "1",
      "--frames", "30"], ["--lengths: no frame count given (e.g. 200,400,800)"]),
    (["bench", "real", "--address", "10.0.0.1:6379"], ["--address 10.0.0.1:6379", "for --backend ray"]),
    (["serve", "--burst", "0.5", "--duration", "0.1"], ["--burst", "0.5"]),
    (["train", "--steps", "-5", "-o", "{tmp}/run"], ["--steps", "-5"]),
    (["train", "--minutes", "0", "-o", "{tmp}/run"], ["--minutes"]),
])
def test_meaningless_options_are_refused(tmp_path, args, needles):
    r = runner.invoke(app, [a.format(tmp=tmp_path) for a in args])
    _one_error_line(r, *needles)
    assert not (tmp_path / "run").exists()


@pytest.mark.parametrize("setting, needle", [("threads=100000", "threads"), ("classes=-1", "classes")])
def test_onnx_detector_settings_out_of_range_are_refused(tiny_video, tmp_path, setting, needle):
    model = Path(__file__).resolve().parents[1] / "src" / "lookalike" / "vision" / "models_data" / "diver_reid.onnx"
    video, _ = tiny_video
    r = _track("--video", video, "--detector", model, "--blob", setting, "-o", tmp_path / "o.txt")
    _one_error_line(r, needle)
    assert not (tmp_path / "o.txt").exists()


def test_eval_refuses_fractional_track_ids_naming_the_line(tmp_path):
    gt, res = _gt_folder(tmp_path)
    lines = (res / "S1.txt").read_text().splitlines(keepends=True)
    lines[3] = lines[3].replace(",1,", ",1.5,", 1)
    (res / "S1.txt").write_text("".join(lines))
    _one_error_line(_eval(gt, res), "S1.txt:4", "not a whole number")


def test_tune_study_and_space_problems_are_one_line(tmp_path):
    seq = _seq(tmp_path / "S1")
    (seq / "gt").mkdir()
    (seq / "gt" / "gt.txt").write_text("".join(GT_ROW.format(f=f, i=1, x=10 + f) for f in range(1, 22)))
    blocker = tmp_path / "file"
    blocker.write_text("")
    tune = ["tune", str(seq), "-o", str(tmp_path / "p.json"), "--trials", "1"]
    _one_error_line(runner.invoke(app, [*tune, "--study", f"sqlite:///{blocker}/x.db"]), "--study", "is a file")
    _one_error_line(runner.invoke(app, [*tune, "--study", f"sqlite:///{seq / 'gt' / 'gt.txt'}"]), "is the input")
    _one_error_line(runner.invoke(app, [*tune, "--study", "nosuchdb://host/x"]), "--study nosuchdb://host/x")
    (tmp_path / "list.json").write_text("[1, 2]")
    _one_error_line(runner.invoke(app, [*tune, "--space", str(tmp_path / "list.json")]), "--space", "got a list")
    assert not (tmp_path / "p.json").exists()


def test_report_on_a_deeply_nested_json_is_one_line(tmp_path):
    deep = tmp_path / "deep.json"
    deep.write_text("[" * 100_000 + "]" * 100_000)
    _one_error_line(runner.invoke(app, ["report", str(deep), "-o", str(tmp_path / "r.html")]), "deep.json",
                    "nested too deeply")
    assert not (tmp_path / "r.html").exists()


@pytest.mark.parametrize("frames", [1, 2, 3])
def test_offline_closed_set_on_a_few_frames_keeps_every_target(tmp_path, frames):
    """Three targets in 1-3 frames: the offline assignment, or where its tracklets are too short to earn an
    identity (one frame), the online result with a note; either way all three, every frame."""
    det = tmp_path / "det.txt"
    det.write_text("".join(f"{f},-1,{10 + 60 * i + f},10,20,40,0.9,-1,-1,-1\n" for f in range(1, frames + 1)
                           for i in range(3)))
    r = _track(det, "-t", "boxtrack", "--targets", "3", "--offline", "-o", tmp_path / "o.txt")
    assert r.exit_code == 0, r.output
    assert ("too few for the offline closed set" in " ".join(r.output.split())) == (frames == 1)
    table = read_mot(tmp_path / "o.txt")
    assert len(table) == 3 * frames and set(table.track_id.tolist()) == {1, 2, 3}


def test_blob_detector_reads_a_folder_of_images(tmp_path):
    import cv2
    import numpy as np

    folder = tmp_path / "img1"
    folder.mkdir()
    for k in range(40):
        image = np.full((120, 160, 3), 90, np.uint8)
        image[40:70, 5 + 3 * k:35 + 3 * k] = 250
        cv2.imwrite(str(folder / f"{k + 1:06d}.png"), image)
    r = _track("--video", folder, "--detector", "blob", "-o", tmp_path / "o.txt")
    assert r.exit_code == 0, r.output
    assert len(read_mot(tmp_path / "o.txt")) >= 30
    empty = tmp_path / "empty"
    empty.mkdir()
    _one_error_line(_track("--video", empty, "--detector", "blob", "-o", tmp_path / "e.txt"), "holds no")


@pytest.mark.parametrize("channels, dtype", [(1, "FLOAT"), (3, "UINT8")])
def test_onnx_model_with_an_input_lookalike_cannot_feed_is_one_line(tiny_video, tmp_path, channels, dtype):
    onnx = pytest.importorskip("onnx")
    pytest.importorskip("onnxruntime")
    from onnx import TensorProto, helper

    x = helper.make_tensor_value_info("images", getattr(TensorProto, dtype), [1, channels, 64, 64])
    y = helper.make_tensor_value_info("out", TensorProto.FLOAT, [1, 5, 1])
    nodes = [helper.make_node("Cast", ["images"], ["f"], to=TensorProto.FLOAT),
             helper.make_node("ReduceMean", ["f"], ["m"], keepdims=1, axes=[1, 2]),
             helper.make_node("Reshape", ["m", "shape"], ["r"]),
             helper.make_node("Tile", ["r", "reps"], ["out"])]
    inits = [helper.make_tensor("shape", TensorProto.INT64, [3], [1, 1, 64]),
             helper.make_tensor("reps", TensorProto.INT64, [3], [1, 5, 1])]
    graph = helper.make_graph(nodes, "odd_input", [x], [y], inits)
    model = helper.make_model(graph, opset_imports=[helper.make_opsetid("", 13)])
    model.ir_version = 8
    path = tmp_path / "odd.onnx"
    onnx.save(model, str(path))
    video, _ = tiny_video
    r = _track("--video", video, "--detector", path, "-o", tmp_path / "o.txt")
    _one_error_line(r, "odd.onnx", "channel" if channels != 3 else "tensor(uint8)")


def test_tune_names_a_missing_folder_and_empty_ground_truth(tmp_path):
    _one_error_line(runner.invoke(app, ["tune", str(tmp_path / "none"), "-o", str(tmp_path / "p.json")]),
                    "none: no such folder")
    seq = _seq(tmp_path / "S1")
    (seq / "gt").mkdir()
    (seq / "gt" / "gt.txt").write_text("")
    _one_error_line(runner.invoke(app, ["tune", str(seq), "-o", str(tmp_path / "p.json"), "--trials", "1"]),
                    "ground truth", "is empty")
    assert not (tmp_path / "p.json").exists()


def test_points_input_problems_name_the_file_and_line(tmp_path):
    _one_error_line(_track("--points", tmp_path, "-o", tmp_path / "o.txt"), "is a folder")
    points = tmp_path / "p.csv"
    points.write_text("frame,x,y\n1,5,5\n2,1e300,5\n")
    _one_error_line(_track("--points", points, "-o", tmp_path / "o.txt"), "p.csv:3", "beyond")
    assert not (tmp_path / "o.txt").exists()


def test_labelling_page_answers_a_deeply_nested_body_with_400_and_exports_concurrently(tmp_path):
    import json
    import threading

    from lookalike.io.robot_sequences import write_robot_sequence
    from lookalike.sim import preset, simulate_robots
    from lookalike.viz.label import open_label_app
    from tests.test_label_server import _request, _serve

    path = write_robot_sequence(tmp_path / "s" / "m3n2-000003.jsonl", simulate_robots(preset("m3n2"), 20, 3))
    server, thread = _serve(open_label_app(path))
    try:
        status, data = _request(server, "POST", "/api/label", "[" * 5_000 + "]" * 5_000)
        assert status == 400 and "nested" in json.loads(data)["error"]
        statuses = []

        def export():
            statuses.append(_request(server, "POST", "/api/export", "{}")[0])

        threads = [threading.Thread(target=export) for _ in range(8)]
        for t in threads:
            t.start()
        for t in threads:
            t.join(30)
        assert statuses == [200] * 8
        assert not [p.name for p in path.parent.iterdir() if ".tmp" in p.name]
    finally:
        server.shutdown()
        server.server_close()
        thread.join(5)


def _recordings(folder: Path, frames: int, label: float | None = None) -> Path:
    """Three labelled robot recordings (m3n2) of ``frames`` frames; ``label``: the first detection's label."""
    import json

    from lookalike.io.robot_sequences import write_robot_sequence
    from lookalike.sim import preset, simulate_robots

    for seed in range(3):
        path = write_robot_sequence(folder / f"m3n2-{seed:06d}.labelled.jsonl",
                                    simulate_robots(preset("m3n2"), frames, seed))
        if label is not None and seed == 0:
            lines = path.read_text().splitlines()
            for i, line in enumerate(lines[1:], start=1):
                record = json.loads(line)
                if record["detections"]["label"]:
                    record["detections"]["label"][0] = label
                    lines[i] = json.dumps(record)
                    break
            path.write_text("\n".join(lines) + "\n")
    return folder


@pytest.mark.parametrize("label", [7, -5, 0.5])
def test_recording_labels_outside_the_team_are_one_line_naming_the_line(tmp_path, label):
    from lookalike.io.robot_sequences import read_robot_sequence

    folder = _recordings(tmp_path / "rec", 20, label)
    with pytest.raises(ValueError, match=r"m3n2-000000\.labelled\.jsonl:\d+: .*labels must be whole numbers from -1"):
        read_robot_sequence(folder / "m3n2-000000.labelled.jsonl")


def test_train_on_recordings_shorter_than_the_sequence_length_has_a_finite_loss(tmp_path):
    pytest.importorskip("torch")
    import csv

    folder = _recordings(tmp_path / "rec", 150)
    r = runner.invoke(app, ["train", "--preset", "m3n2", "--recordings", str(folder), "-o", str(tmp_path / "run"),
                            "--steps", "2", "--sequence-length", "450", "--batch-size", "2", "--validate-every", "1"])
    assert r.exit_code == 0, r.output
    with (tmp_path / "run" / "training_log.csv").open() as fh:
        losses = [float(row["loss"]) for row in csv.DictReader(fh) if int(row["step"]) > 0]
    assert losses and all(loss == loss and loss < 1e6 for loss in losses), losses  # no NaN (padding only skipped)


def test_nms_memory_is_linear_in_the_boxes_and_keeps_the_same_boxes():
    import tracemalloc

    import numpy as np

    from lookalike.vision import nms as nms_module

    rng = np.random.default_rng(0)

    def boxes(n):
        return np.hstack([rng.uniform(0, 640, (n, 2)), rng.uniform(5, 60, (n, 2))]), rng.random(n)

    xywh, score = boxes(2000)
    by_rows = nms_module.nms(xywh, score, 0.45)
    old = nms_module.MATRIX_BOXES
    nms_module.MATRIX_BOXES = 10**9
    try:
        assert np.array_equal(nms_module.nms(xywh, score, 0.45), by_rows)
    finally:
        nms_module.MATRIX_BOXES = old
    xywh, score = boxes(10_000)
    tracemalloc.start()
    try:
        kept = nms_module.nms(xywh, score, 0.45)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert 0 < len(kept) < 10_000 and peak < 50e6, peak  # the 10,000 x 10,000 overlap matrix alone is 800 MB


def test_points_above_the_per_frame_limit_are_one_line_naming_the_frame(tmp_path):
    from lookalike.pipeline.closed import MAX_POINTS_PER_FRAME

    points = tmp_path / "p.csv"
    rows = [f"1,{i},{i}\n" for i in range(10)] + [f"2,{i},{2 * i}\n" for i in range(MAX_POINTS_PER_FRAME + 1)]
    points.write_text("".join(rows))
    _one_error_line(_track("--points", points, "-o", tmp_path / "o.txt"), "frame 2 has",
                    f"at most {MAX_POINTS_PER_FRAME}")
    assert not (tmp_path / "o.txt").exists()


def test_a_truncated_video_is_named_as_such(tmp_path):
    import numpy as np

    from lookalike.viz.video import VideoWriter

    rows = []
    with VideoWriter(tmp_path / "full.mp4", fps=10) as writer:
        for k in range(60):
            image = np.full((120, 160, 3), 90, np.uint8)
            image[40:70, 5 + 2 * k:35 + 2 * k] = 250
            writer.write(image)
            rows.append(f"{k + 1},-1,{5 + 2 * k},40,30,30,0.9,-1,-1,-1\n")
    (tmp_path / "det.txt").write_text("".join(rows))
    data = (tmp_path / "full.mp4").read_bytes()
    (tmp_path / "cut.mp4").write_bytes(data[: len(data) // 2])
    for args in (["--detections", tmp_path / "det.txt"], ["--detector", "blob"]):
        r = _track("--video", tmp_path / "cut.mp4", *args, "-o", tmp_path / "o.txt")
        assert r.exit_code == 2 and "Traceback" not in r.output, r.output
        assert "declares 60 frames but only" in r.output and "truncated" in r.output, r.output
        assert not (tmp_path / "o.txt").exists()
        # run as the program: FFmpeg's own lines ("[h264 @ ...] Invalid NAL unit size") are not printed before it
        env = {k: v for k, v in os.environ.items() if k != "OPENCV_FFMPEG_LOGLEVEL"}
        proc = subprocess.run([sys.executable, "-m", "lookalike", "track", "--video", str(tmp_path / "cut.mp4"),
                               *map(str, args), "-o", str(tmp_path / "o.txt")], capture_output=True, text=True,
                              env={**env, "COLUMNS": "200"}, timeout=120)
        lines = [line for line in (proc.stdout + proc.stderr).splitlines()
                 if line.strip() and not line.startswith("warning:")]  # (all scores 0.9: a warning may come first)
        assert proc.returncode == 2 and len(lines) == 1 and lines[0].startswith("error: video:"), lines


def test_onnx_ssd_outputs_that_do_not_match_name_the_model(tiny_video, tmp_path):
    import numpy as np

    from tests.test_onnx_detector import _constant_model

    model = _constant_model(tmp_path / "ssd.onnx", {"boxes": np.zeros((1, 10, 4)), "scores": np.zeros((1, 7, 3))})
    video, _ = tiny_video
    r = _track("--video", video, "--detector", model, "-o", tmp_path / "o.txt")
    _one_error_line(r, "ssd.onnx", "do not match")


def test_a_one_pixel_video_with_the_blob_detector_is_one_line(tmp_path):
    import cv2
    import numpy as np

    writer = cv2.VideoWriter(str(tmp_path / "one.avi"), cv2.VideoWriter_fourcc(*"MJPG"), 10, (1, 1))
    for k in range(20):
        writer.write(np.full((1, 1, 3), 10 * k, np.uint8))
    writer.release()
    _one_error_line(_track("--video", tmp_path / "one.avi", "--detector", "blob", "-o", tmp_path / "o.txt"),
                    "one.avi", "1x1 px")


@pytest.mark.parametrize("body", ['{"schema": "SCHEMA", "header": 5, "tables": 5}',
                                  '[{"Setup": "a", "Tracker": "b", "Success rate (%)": "x"}]',
                                  '[{"Setup": [1], "Tracker": {"x": 1}, "Success rate (%)": null}]',
                                  '{"T": {"S": {"HOTA": [1]}}}', '[{"Scenario": 1, "IDF1": "z", "Tracker": 3}]'])
def test_report_on_wrong_typed_json_is_one_line_naming_the_file(tmp_path, body):
    from lookalike.io.results import SCHEMA_ID

    doc = tmp_path / "wt.json"
    doc.write_text(body.replace("SCHEMA", SCHEMA_ID))
    _one_error_line(runner.invoke(app, ["report", str(doc), "-o", str(tmp_path / "r.html")]), "wt.json")
    assert not (tmp_path / "r.html").exists()


def test_an_output_beside_the_inputs_that_is_not_read_may_be_replaced(tmp_path):
    gt, res = _gt_folder(tmp_path)
    (res / "scores.json").write_text("an earlier run\n")  # in the results folder, but not a result eval reads
    r = _eval(gt, res, "--json", res / "scores.json")
    assert r.exit_code == 0, r.output
    assert (res / "scores.json").read_text().startswith("{")


def test_a_folder_given_as_a_file_and_a_file_given_as_the_results_folder_are_named(tmp_path):
    from lookalike.eval.folders import evaluate_folders
    from lookalike.io import read_mot
    from lookalike.io.stream import DetectionStream

    with pytest.raises(FileNotFoundError, match="is a folder, not a file"):
        read_mot(tmp_path)
    with pytest.raises(FileNotFoundError, match="is a folder, not a file"):
        DetectionStream(tmp_path).check()
    with pytest.raises(FileNotFoundError, match="no such file"):
        read_mot(tmp_path / "missing.txt")
    seq = tmp_path / "seq"
    (seq / "gt").mkdir(parents=True)
    (seq / "gt" / "gt.txt").write_text("1,1,10,10,20,20,1,1,1\n")
    (seq / "seqinfo.ini").write_text("[Sequence]\nname=seq\nseqLength=1\nframeRate=10\nimWidth=100\nimHeight=100\n")
    result = tmp_path / "seq.txt"
    result.write_text("1,1,10,10,20,20,1,-1,-1,-1\n")
    with pytest.raises(ValueError, match=r"seq\.txt: is a file; give the folder .*\(seq\.txt, \.\.\.\)"):
        evaluate_folders(seq, result)
    assert evaluate_folders(seq, tmp_path)["COMBINED"]["IDF1"] == pytest.approx(1.0)  # the folder is scored
    with pytest.raises(ValueError, match=r"gt\.txt: is a file; give the sequence folder that holds gt/gt\.txt"):
        evaluate_folders(seq / "gt" / "gt.txt", tmp_path)  # (it said "no sequence with gt/gt.txt")


def test_the_python_api_names_bad_rows_reports_features_and_boxes(tmp_path):
    import numpy as np

    import lookalike as la
    from lookalike.types import Beacons, Detections, Frame

    out = tmp_path / "w.txt"
    with pytest.raises(ValueError, match=r"w.txt: rows\[0\]: result rows need shape \(k, 10\), got \(2, 5\)"):
        la.write_mot(out, [np.zeros((2, 5))])  # (once reshaped into one row of ten)
    row = np.array([[1, 1, 10, 10, 20, 20, 1, -1, -1, -1.0]])
    for column, value, why in ((0, 0, "invalid frame"), (4, -20, "negative width or height")):
        wrong = row.copy()
        wrong[0, column] = value
        with pytest.raises(ValueError, match=why):
            la.write_mot(out, wrong)  # what read_mot would refuse is never written
    assert not out.exists()

    tracker = la.make_tracker("set", n_agents=3)
    reports = Beacons(agent_id=[1, 2, 3], t_sent=[0.0, 0.0, 0.0], t_received=[0.0, 0.0, 0.0], heading=[0.1, 0.2, 0.3])
    with pytest.raises(ValueError, match=r"Beacons.agent_id: 3 is no agent of this tracker \(n_agents=3"):
        tracker.update(Frame(index=0, time=0.0, detections=Detections.empty(), beacons=reports))

    for name in ("deepsort", "diversort"):
        tracker = la.make_tracker(name)
        box = np.array([[10.0, 10, 20, 20]])
        tracker.update(Frame(index=0, time=0.0, detections=Detections(xywh=box, feature=np.ones((1, 16)) / 4)))
        with pytest.raises(ValueError, match="Detections.feature: vectors of length 8, but .* length 16"):
            tracker.update(Frame(index=1, time=0.1, detections=Detections(xywh=box, feature=np.ones((1, 8)) / 8**0.5)))

    for name in ("sort", "deepsort"):  # (boxtrack takes degenerate boxes: test_boxtrack_kernels)
        with pytest.raises(ValueError, match=f"{name}: Detections.xywh row 1 is 0 wide and 5 high"):
            la.make_tracker(name).update(Frame(index=0, time=0.0, detections=Detections(
                xywh=np.array([[1.0, 1, 5, 5], [2, 2, 0, 5]]), feature=np.eye(2))))


def test_an_integer_column_given_fractions_is_refused_not_truncated():
    import numpy as np

    from lookalike.types import Beacons, Detections

    with pytest.raises(ValueError, match="Detections.label: 0.5 is not a whole number"):
        Detections(xywh=np.ones((2, 4)), label=[0.5, 1])
    with pytest.raises(ValueError, match="Beacons.agent_id: 1.5 is not a whole number"):
        Beacons(agent_id=[1.5], t_sent=[0.0], t_received=[0.0], heading=[0.0])
    assert Detections(xywh=np.ones((2, 4)), label=[0.0, 1.0]).label.tolist() == [0, 1]  # whole floats are fine


@pytest.mark.parametrize("command", [["bench", "ident"], ["bench", "shuffle"], ["bench", "recovery"],
                                     ["bench", "pixels"], ["demo", "--quick", "-o", "{tmp}/out"]])
def test_a_negative_seed_is_refused_naming_the_option(tmp_path, command):
    r = runner.invoke(app, [a.format(tmp=tmp_path) for a in command] + ["--seed", "-1"])
    assert r.exit_code == 2 and "Traceback" not in r.output and "--seed" in r.output, r.output
    assert not (tmp_path / "out").exists()


def test_run_demo_refuses_a_negative_seed_before_writing(tmp_path):
    from lookalike.demo import QUICK, run_demo

    with pytest.raises(ValueError, match="seed: a whole number >= 0, got -1"):
        run_demo(tmp_path / "out", -1, QUICK, "m3n2")
    assert not (tmp_path / "out").exists()
