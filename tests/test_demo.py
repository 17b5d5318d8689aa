"""``lookalike demo --quick`` end to end, ``lookalike render`` and ``lookalike report``."""

from __future__ import annotations

import json
import re

import numpy as np
import pytest

pytest.importorskip("cv2")
pytest.importorskip("matplotlib")

from typer.testing import CliRunner

from lookalike.cli import app
from lookalike.demo import QUICK, lstm_status
from lookalike.io.results import validate
from lookalike.viz import read_frames, video_info

runner = CliRunner()


@pytest.fixture(scope="module")
def demo_out(tmp_path_factory):
    out = tmp_path_factory.mktemp("demo") / "demo-out"
    r = runner.invoke(app, ["demo", "--quick", "-o", str(out)])
    assert r.exit_code == 0, r.output
    return out, r.output


def test_demo_writes_every_file(demo_out):
    out, text = demo_out
    for name in ("robots.mp4", "robots.gif", "robots-still.png", "robots-birdseye.png", "divers.mp4", "divers.gif",
                 "divers-still.png", "divers-raw.mp4", "divers-idf1.png", "robots-ident.png", "report.html",
                 "robots-ident.json", "divers.json", "divers-sort.txt", "divers-diversort.txt"):
        assert (out / name).is_file() and (out / name).stat().st_size > 0, name
    assert "report.html" in text and "Try next" in text


def test_demo_videos_start_after_the_warm_up_on_their_still(demo_out):
    import cv2

    out, _ = demo_out
    for name, frames in (("robots", QUICK.robot_frames), ("divers", QUICK.diver_video_frames)):
        clip = list(read_frames(out / f"{name}.mp4"))
        assert 0 < len(clip) <= frames, name  # the warm-up's frames are left out
        still = cv2.imread(str(out / f"{name}-still.png"))
        assert clip[0].shape == still.shape  # the caption and legend band above the picture included
        off = (np.abs(clip[0].astype(int) - still.astype(int)).max(axis=2) > 60).mean()
        assert off < 0.0075, name  # the first frame is the still (the next frame differs in 1-8 % of its pixels)
    assert video_info(out / "divers-raw.mp4")[0] == QUICK.diver_video_frames  # the raw video has every frame


def test_demo_tables_cover_trackers_and_lstm_presence(demo_out):
    out, text = demo_out
    ident_doc = json.loads((out / "robots-ident.json").read_text())
    divers_doc = json.loads((out / "divers.json").read_text())
    validate(ident_doc)
    validate(divers_doc)
    ident, divers = ident_doc["tables"]["ident"], divers_doc["tables"]["divers"]
    assert {r["tracker"] for r in divers} == {"sort", "deepsort", "diversort"}
    assert len({r["sequence"] for r in divers}) == QUICK.diver_scenarios
    for setup, label in (("m3n2", "M=3, N=2"), ("m5n3", "M=5, N=3"), ("m10n7", "M=10, N=7")):
        names = {r["tracker"] for r in ident if r["dataset"] == setup}
        assert {"kalman_ha", "kalman_ha2", "jpda"} <= names
        if lstm_status(setup) is None:
            assert "lstm" in names
        else:
            assert "lstm" not in names and f"no shipped LSTM weights for {label}" in " ".join(text.split())
    for r in ident:
        assert 0 <= r["metrics"]["success_rate"] <= 1
    html = (out / "report.html").read_text()
    assert len(re.findall(r'<img src="data:image/(png|gif);base64,', html)) >= 3
    assert html.count('<video controls') == 2 and html.count('src="data:video/mp4;base64,') == 2
    assert html.count('poster="data:image/png;base64,') == 2 and html.count('<div class="legend"') == 2
    assert 'href="robots.mp4"' in html and 'href="divers.mp4"' in html


def test_render_overlays_demo_tracks(demo_out, tmp_path):
    out, _ = demo_out
    target = tmp_path / "sort.mp4"
    r = runner.invoke(app, ["render", "--video", str(out / "divers-raw.mp4"), "--tracks", str(out / "divers-sort.txt"),
                            "-o", str(target), "--gif", str(tmp_path / "sort.gif")])
    assert r.exit_code == 0, r.output
    assert video_info(target)[0] == video_info(out / "divers-raw.mp4")[0]
    assert len(list(read_frames(target))) == QUICK.diver_video_frames
    assert (tmp_path / "sort.gif").stat().st_size > 0


def test_render_rejects_missing_inputs(tmp_path):
    tracks = tmp_path / "t.txt"
    tracks.write_text("1,1,5,5,10,10,1,-1,-1,-1\n")
    r = runner.invoke(app, ["render", "--video", str(tmp_path / "none.mp4"), "--tracks", str(tracks),
                            "-o", str(tmp_path / "o.mp4")])
    assert r.exit_code != 0 and "none.mp4" in r.output


def test_report_from_results(demo_out, tmp_path):
    out, _ = demo_out
    evaluation = {"sort": {"seq-a": {"IDF1": 0.5, "HOTA": 0.4, "MOTA": 0.6, "IDSW": 3},
                           "COMBINED": {"IDF1": 0.5, "HOTA": 0.4, "MOTA": 0.6, "IDSW": 3}}}
    (tmp_path / "eval.json").write_text(json.dumps(evaluation))
    target = tmp_path / "r.html"
    r = runner.invoke(app, ["report", str(out / "robots-ident.json"), str(out / "divers.json"),
                            str(tmp_path / "eval.json"), "-o", str(target)])
    assert r.exit_code == 0, r.output
    html = target.read_text()
    assert html.count("data:image/png;base64,") == 3
    assert "seq-a" in html and "m10n7" in html
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps({"rows": 3}))
    r = runner.invoke(app, ["report", str(bad), "-o", str(target)])
    assert r.exit_code != 0 and "bad.json" in r.output


def test_demo_rejects_unknown_preset(tmp_path):
    r = runner.invoke(app, ["demo", "--quick", "--robot-preset", "m99", "-o", str(tmp_path)])
    assert r.exit_code != 0 and "m99" in r.output


def test_html_report_escapes_and_rejects_unknown_images(tmp_path):
    from lookalike.viz import HtmlReport

    doc = HtmlReport("<b>x</b>")
    doc.table([{"a": "<script>", "b": np.float64(1.5)}])
    with pytest.raises(ValueError, match="image"):
        doc.image(tmp_path / "x.bmp")
    html = doc.render()
    assert "<script>" not in html and "&lt;script&gt;" in html


def test_demo_interrupt_exits_130_with_a_message(monkeypatch, tmp_path):
    import lookalike.cli.demo as demo_module

    def interrupted(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(demo_module, "run_demo", interrupted)
    r = runner.invoke(app, ["demo", "--quick", "-o", str(tmp_path)])
    assert r.exit_code == 130 and "Interrupted" in r.output


def test_video_interrupted_midway_is_still_decodable(tmp_path):
    from lookalike.viz import VideoWriter

    frame = np.full((48, 64, 3), 90, np.uint8)
    with pytest.raises(KeyboardInterrupt), VideoWriter(tmp_path / "v.mp4", fps=10) as w:
        for k in range(30):
            if k == 12:
                raise KeyboardInterrupt
            w.write(frame)
    assert len(list(read_frames(tmp_path / "v.mp4"))) == 12


def test_render_birdseye_needs_no_video(tmp_path):
    rows = "\n".join(f"{f},1,0,0,0,0,1,{0.1 * f:.2f},0.5,0" for f in range(1, 11))
    (tmp_path / "w.txt").write_text(rows + "\n")
    r = runner.invoke(app, ["render", "--birdseye", "--tracks", str(tmp_path / "w.txt"), "-o", str(tmp_path / "b.mp4")])
    assert r.exit_code == 0, r.output
    assert video_info(tmp_path / "b.mp4")[0] == 10
    r = runner.invoke(app, ["render", "--tracks", str(tmp_path / "w.txt"), "-o", str(tmp_path / "c.mp4")])
    assert r.exit_code != 0 and "--video" in r.output


def test_demo_rerun_recording(tmp_path):
    pytest.importorskip("rerun", reason="the optional rerun-sdk is not installed")
    rrd = tmp_path / "demo.rrd"
    r = runner.invoke(app, ["demo", "--quick", "-o", str(tmp_path / "out"), "--rerun-save", str(rrd)])
    assert r.exit_code == 0, r.output
    assert rrd.stat().st_size > 100_000  # the logged frames are in it
    assert f"rerun {rrd}" in " ".join(r.output.split())


def test_rerun_missing_is_a_clear_error(monkeypatch, tmp_path):
    import builtins

    real_import = builtins.__import__

    def no_rerun(name, *args, **kwargs):
        if name == "rerun" or name.startswith("rerun."):
            raise ImportError(name)
        return real_import(name, *args, **kwargs)

    monkeypatch.setattr(builtins, "__import__", no_rerun)
    r = runner.invoke(app, ["demo", "--quick", "-o", str(tmp_path), "--rerun-save", str(tmp_path / "x.rrd")])
    assert r.exit_code == 2 and "--rerun-save:" in r.output and "'rerun' extra" in r.output


def test_demo_rerun_save_errors_name_the_option(tmp_path):
    try:
        import rerun  # noqa: F401
    except ImportError:
        r = runner.invoke(app, ["demo", "--quick", "--rerun-save", str(tmp_path / "x.rrd"), "-o", str(tmp_path)])
        assert r.exit_code == 2 and "--rerun-save:" in r.output and "Traceback" not in r.output
    else:
        pytest.skip("rerun-sdk is installed: no error to check")
