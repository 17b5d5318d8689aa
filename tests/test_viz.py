"""viz: annotation, video writing (decodes with OpenCV, same frame count), plots, overlay."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

cv2 = pytest.importorskip("cv2")

from lookalike.io import MotTable
from lookalike.viz import (
    Tails,
    VideoWriter,
    birdseye_plot,
    draw_box_tracks,
    grouped_bar_chart,
    identity_colour,
    read_frames,
    video_info,
)
from lookalike.viz.overlay import overlay_tracks


def _frames(n: int, w: int = 96, h: int = 64) -> list[np.ndarray]:
    rng = np.random.default_rng(0)
    return [np.full((h, w, 3), 40, np.uint8) + rng.integers(0, 20, (h, w, 3), dtype=np.uint8) for _ in range(n)]


def test_identity_colours_are_stable_and_distinct():
    assert identity_colour(3) == identity_colour(3)
    assert len({identity_colour(i) for i in range(10)}) == 10
    assert identity_colour(-1) != identity_colour(0)


def test_draw_box_tracks_paints_in_identity_colour():
    img = np.zeros((60, 80, 3), np.uint8)
    tails = Tails(5)
    for k in range(3):
        draw_box_tracks(img, k, np.array([2]), np.array([[10.0 + k, 20.0, 30.0, 25.0]]), tails)
    colour = np.array(identity_colour(2))
    assert (np.abs(img.reshape(-1, 3).astype(int) - colour).sum(axis=1) < 10).sum() > 50
    with pytest.raises(ValueError, match="ids"):
        draw_box_tracks(img, 0, np.array([1, 2]), np.zeros((1, 4)), tails)


def test_video_writer_round_trip_and_gif(tmp_path):
    frames = _frames(17)
    with VideoWriter(tmp_path / "v.mp4", fps=10, gif=tmp_path / "v.gif", gif_every=2) as w:
        for f in frames:
            w.write(f)
    decoded = list(read_frames(tmp_path / "v.mp4"))
    assert len(decoded) == 17
    assert decoded[0].shape == frames[0].shape
    n, fps, size = video_info(tmp_path / "v.mp4")
    assert (n, size) == (17, (96, 64)) and fps == pytest.approx(10)
    from PIL import Image

    with Image.open(tmp_path / "v.gif") as gif:
        assert gif.n_frames == 9


def test_video_writer_rejects_bad_frames(tmp_path):
    with VideoWriter(tmp_path / "v.mp4", fps=10) as w:
        w.write(_frames(1)[0])
        with pytest.raises(ValueError, match="image"):
            w.write(np.zeros((10, 10, 3), np.uint8))
        with pytest.raises(ValueError, match="image"):
            w.write(np.zeros((64, 96), np.uint8))
    with pytest.raises(ValueError, match="fps"):
        VideoWriter(tmp_path / "x.mp4", fps=0)


def test_overlay_keeps_the_input_frame_count(tmp_path):
    with VideoWriter(tmp_path / "in.mp4", fps=12) as w:
        for f in _frames(23, 160, 120):
            w.write(f)
    rows = np.array([[k, 1, 10 + k, 20, 30, 40, 1, -1, -1, -1] for k in range(1, 20)]
                    + [[5, 2, 80, 30, 20, 20, 1, -1, -1, -1]], dtype=float)
    n = overlay_tracks(tmp_path / "in.mp4", MotTable.from_rows(rows), tmp_path / "out.mp4")
    assert n == 23
    out = list(read_frames(tmp_path / "out.mp4"))
    assert len(out) == 23
    src = list(read_frames(tmp_path / "in.mp4"))
    def change(k):
        return np.abs(out[k].astype(int) - src[k].astype(int)).mean()

    assert change(4) > change(22)


def test_render_warns_when_tracks_are_not_drawn(tmp_path):
    """A detection file (ids -1), an empty file or tracks past the video's end used to render a plain copy silently."""
    from typer.testing import CliRunner

    from lookalike.cli import app

    folder = tmp_path / "img1"
    folder.mkdir()
    for k, f in enumerate(_frames(3)):
        cv2.imwrite(str(folder / f"{k + 1:06d}.jpg"), f)
    row = "1,1,5,5,20,20,1,-1,-1,-1\n"
    cases = {"1,-1,5,5,20,20,0.9,-1,-1,-1\n": "every id is negative (a detection file?)", "": "no rows",
             row + "9" + row[1:]: "1 rows of frames 4-9 lie past the video's 3 frames", row: None}
    for text, needle in cases.items():
        tracks = tmp_path / "t.txt"
        tracks.write_text(text)
        r = CliRunner().invoke(app, ["render", "--tracks", str(tracks), "--video", str(folder),
                                     "-o", str(tmp_path / "o.mp4")])
        assert r.exit_code == 0, r.output
        assert (needle in r.output) if needle else "warning" not in r.output, r.output


def test_overlay_reads_image_folders(tmp_path):
    folder = tmp_path / "img1"
    folder.mkdir()
    for k, f in enumerate(_frames(5)):
        cv2.imwrite(str(folder / f"{k + 1:06d}.jpg"), f)
    rows = np.array([[1, 1, 5, 5, 20, 20, 1, -1, -1, -1]], dtype=float)
    assert overlay_tracks(folder, MotTable.from_rows(rows), tmp_path / "o.mp4") == 5
    (tmp_path / "empty").mkdir()
    with pytest.raises(ValueError, match="no images"):
        overlay_tracks(tmp_path / "empty", MotTable.from_rows(rows), tmp_path / "x.mp4")


def test_plots_write_pngs(tmp_path):
    t = np.cumsum(np.random.default_rng(1).normal(0, 0.1, (50, 2, 2)), axis=0)
    p = birdseye_plot(tmp_path / "b.png", t, t + 0.05, field_m=(9, 6), observer=np.array([-4.3, 0.0]))
    assert cv2.imread(str(p)).shape[0] > 100
    rows = [{"S": "a", "T": "x", "V": 50.0}, {"S": "a", "T": "y", "V": 70.0}, {"S": "b", "T": "x", "V": 10.0}]
    assert cv2.imread(str(grouped_bar_chart(tmp_path / "g.png", rows, "S", "T", "V"))) is not None
    with pytest.raises(ValueError, match="column"):
        grouped_bar_chart(tmp_path / "g.png", rows, "S", "T", "missing")
    with pytest.raises(ValueError, match="T, N, 2"):
        birdseye_plot(tmp_path / "b.png", t, t[:, :1])


def test_birdseye_video_has_one_frame_per_frame_number(tmp_path):
    from lookalike.viz.overlay import birdseye_video

    rows = []
    for f in range(1, 16):
        rows.append([f, 1, -1, -1, -1, -1, 1, 0.1 * f, 1.0, 0])
        if f % 2:
            rows.append([f, 2, -1, -1, -1, -1, 1, 2.0, -0.2 * f, 0])
    n = birdseye_video(MotTable.from_rows(np.array(rows, dtype=float)), tmp_path / "b.mp4", size_px=200)
    assert n == 15 and len(list(read_frames(tmp_path / "b.mp4"))) == 15
    unset = np.array([[1, 1, 5, 5, 10, 10, 1, -1, -1, -1]], dtype=float)
    with pytest.raises(ValueError, match="world"):
        birdseye_video(MotTable.from_rows(unset), tmp_path / "x.mp4")


def test_eval_results_with_some_metrics_only(tmp_path):
    import json

    from lookalike.viz import HtmlReport
    from lookalike.viz.results import add_results, load_results

    path = tmp_path / "e.json"
    path.write_text(json.dumps({"sort": {"a": {"MOTA": -0.25, "IDSW": 4}, "b": {"MOTA": 0.5, "IDSW": 1}}}))
    kind, rows = load_results(path)
    assert kind == "eval" and rows[0] == {"Tracker": "sort", "Sequence": "a", "MOTA": -25.0, "IDSW": 4}
    doc = HtmlReport("t")
    assert len(add_results(doc, kind, rows, tmp_path, "c")) == 1
    path.write_text(json.dumps({"sort": {"a": {"Recall": 0.5}}}))
    with pytest.raises(ValueError, match="none of"):
        load_results(path)


def test_report_names_a_binary_file_or_a_folder(tmp_path):
    from lookalike.viz.results import load_results

    video = tmp_path / "v.mp4"
    video.write_bytes(b"\x00\x00\x00\x18ftypmp42\xe8\xff")
    with pytest.raises(ValueError, match=r"v\.mp4:1: not UTF-8 text"):  # (was the codec's message, no file)
        load_results(video)
    with pytest.raises(ValueError, match="results: a folder, not a file"):
        load_results(tmp_path)


def test_tails_break_at_jumps_and_keep_a_limited_length():
    from lookalike.viz import Tails

    tails = Tails(length=5, max_jump=1.0)
    for f in range(4):
        tails.add(f, 7, np.array([0.1 * f, 0.0]))
    tails.add(4, 7, np.array([50.0, 0.0]))  # an identity switch: a jump
    (_, pts), = tails.items()
    assert len(pts) == 5 and np.isnan(pts[-2]).all() and pts[-1][0] == 50.0


def test_labels_avoid_each_other():
    from lookalike.viz import LabelSpace, draw_label

    img = np.zeros((240, 320, 3), np.uint8)
    space = LabelSpace()
    a = draw_label(img, "false positive", (100, 100), (200, 200, 200), labels=space, box=(100, 100, 130, 160))
    b = draw_label(img, "robot 2", (105, 100), (0, 140, 255), labels=space, box=(105, 100, 135, 160))
    assert a[2] <= b[0] or b[2] <= a[0] or a[3] <= b[1] or b[3] <= a[1]  # no overlap


def test_robot_labels_are_one_based_and_diver_boxes_are_true_false_or_missed():
    from lookalike.viz.divers_scene import true_false_missed
    from lookalike.viz.robots_scene import robot_label

    assert robot_label(0) == "robot 1" and robot_label(-1) == "false positive"
    gt = np.array([[1, 1, 0, 0, 10, 10, 1, 1, 1.0], [1, 2, 50, 50, 10, 10, 1, 1, 1.0]])
    on, missed = true_false_missed(np.array([[1, 1, 10, 10], [100, 100, 10, 10]], float), gt)
    assert on.tolist() == [True, False] and missed.tolist() == [[50, 50, 10, 10]]


def test_robot_video_starts_where_every_label_has_been_right_for_a_while():
    from lookalike.viz.robots_scene import warm_up_end

    truth = [np.array([0, -1])] * 3 + [np.array([], int)] + [np.array([1])] * 8
    right = [np.array([0, -1])] * 3 + [np.array([], int)] + [np.array([1])] * 8
    wrong_first = [np.array([1, -1])] + right[1:]
    assert warm_up_end(right, truth, hold=4) == 0
    assert warm_up_end(wrong_first, truth, hold=4) == 1
    slip = right[:2] + [np.array([0, 2])] + right[3:]  # wrong at frame 2; frame 3 has no robot in view
    assert warm_up_end(slip, truth, hold=4) == 4
    assert warm_up_end([np.array([], int)] * 3, [np.array([], int)] * 3, hold=2) is None  # no robot ever seen
    never = [np.array([2])] * 12
    assert warm_up_end(never, truth[4:] * 2, hold=4) is None
    assert warm_up_end(wrong_first, truth, hold=4, latest=1) is None  # not by frame 1
    late = [np.array([1, -1])] * 3 + [np.array([], int)] + [np.array([2])] * 6 + right[10:]
    assert warm_up_end(late, truth, hold=4) == 10  # right from frame 10 to the end (2 frames) counts


def test_header_band_keeps_the_picture_whole_and_its_height_fixed():
    from lookalike.viz.annotate import with_header

    img = _frames(1, w=320, h=120)[0]
    legend = [("a colour per track", (0, 140, 255), False), ("missed", (255, 255, 255), True),
              ("a long legend entry that needs its own row", (0, 0, 230), False)]
    a = with_header(img, ["caption", "frame 1"], legend)
    b = with_header(img, ["another caption, longer", "frame 200"], legend)
    assert a.shape == b.shape and a.shape[1] == 320 and a.shape[0] > 120 + 2 * 18
    assert np.array_equal(a[-120:], img)  # the picture is below the band, untouched
    assert with_header(img, ["x"], legend[:2]).shape[0] < with_header(img, ["x"], legend).shape[0]  # rows wrap


def test_report_embeds_small_videos_and_links_large_ones(tmp_path, monkeypatch):
    import lookalike.viz.report as report_module
    from lookalike.viz import HtmlReport

    with VideoWriter(tmp_path / "v.mp4", fps=10) as w:
        for f in _frames(5):
            w.write(f)
    cv2.imwrite(str(tmp_path / "p.png"), _frames(1)[0])
    doc = HtmlReport("r")
    assert doc.video(tmp_path / "v.mp4", "clip", relative_to=tmp_path, poster=tmp_path / "p.png",
                     legend=[("missed", (255, 255, 255), True)])
    html = doc.render()
    assert 'src="data:video/mp4;base64,' in html and 'poster="data:image/png;base64,' in html
    assert 'href="v.mp4"' in html and "embedded here" in html and "border-style:dashed" in html
    monkeypatch.setattr(report_module, "EMBED_MAX_BYTES", 10)
    doc = HtmlReport("r")
    assert not doc.video(tmp_path / "v.mp4", "clip", relative_to=tmp_path)
    html = doc.render()
    assert 'src="v.mp4"' in html and "data:video" not in html and "played from" in html
    with pytest.raises(ValueError, match="video"):
        doc.video(tmp_path / "none.mp4", "clip")


@pytest.mark.parametrize("suffix", [".avi", ".mkv", ".mp4"])
def test_video_writer_gives_each_container_only_its_own_options(tmp_path, capfd, caplog, suffix):
    pytest.importorskip("av")
    from lookalike.io.video_frames import source_frames
    from lookalike.viz.video import VideoWriter

    path = tmp_path / f"v{suffix}"
    with VideoWriter(path, fps=10) as writer:
        for k in range(4):
            writer.write(np.full((24, 32, 3), 60 * k, np.uint8))
    said = capfd.readouterr().err + "".join(r.getMessage() for r in caplog.records)  # PyAV warns through logging
    assert "options were not used" not in said
    assert source_frames(path)[1] == 4


def test_divers_results_of_both_detection_levels_keep_each_level_apart(tmp_path):
    from lookalike.bench.divers import diver_results
    from lookalike.viz.results import load_results

    def rows(idf1: float) -> list[dict]:
        cells = {"Location": "pool", "DP": 90.0, "DR": 70.0, "IDF1": idf1, "IDP": 80.0, "IDR": 60.0, "IDSW": 1,
                 "Frag": 2}
        return [{"Scenario": s, "Tracker": "sort", **cells} for s in ("pool_pair", "ALL")]

    path = diver_results({"sim": rows(50.0), "paper": rows(20.0)}, 30, 0, "lookalike bench divers").write(
        tmp_path / "d.json")
    kind, table = load_results(path)
    assert kind == "divers"
    assert [(r["Scenario"], r["IDF1"]) for r in table] == [
        ("pool_pair (sim)", 50.0), ("ALL (sim)", 50.0), ("pool_pair (paper)", 20.0), ("ALL (paper)", 20.0)]
    one = diver_results({"sim": rows(50.0)}, 30, 0, "lookalike bench divers").write(tmp_path / "one.json")
    assert [r["Scenario"] for r in load_results(one)[1]] == ["pool_pair", "ALL"]


def test_report_shows_the_tables_of_any_bench_results_file(tmp_path):
    from typer.testing import CliRunner

    from lookalike.cli import app
    from lookalike.io.results import Results
    from lookalike.viz.results import load_results

    doc = Results("bench real", command="lookalike bench real")
    doc.add("datasets", dataset="mot15", tracker="sort", combined=True,
            metrics={"hota": 0.4526, "mota": -0.125, "idsw": 6, "frames_per_s": 651.8})
    doc.add("sequences", dataset="mot15", sequence="TUD-Campus", tracker="sort", metrics={"idf1": 0.6065})
    doc.add("ranking", dataset=None, tracker="sort", combined=True, metrics={"rank": 1, "mean_rank": None})
    path = doc.write(tmp_path / "real.json")
    kind, rows = load_results(path)
    assert kind == "tables"
    assert rows[0] == {"Table": "datasets", "Dataset": "mot15", "Tracker": "sort", "hota (%)": 45.26,
                       "mota (%)": -12.5, "idsw": 6, "frames_per_s": 651.8}
    assert rows[1]["Sequence"] == "TUD-Campus" and rows[2] == {"Table": "ranking", "Dataset": "all", "Tracker": "sort",
                                                               "rank": 1, "mean_rank": ""}
    r = CliRunner().invoke(app, ["report", str(path), "-o", str(tmp_path / "r.html")])
    assert r.exit_code == 0, r.output
    html = (tmp_path / "r.html").read_text()
    assert all(f"<h2>real.json: {t}</h2>" in html for t in ("datasets", "sequences", "ranking"))
    assert "<th>hota (%)</th>" in html and ">45.26<" in html


def test_an_atomic_video_interrupted_keeps_the_earlier_one_and_leaves_no_temporary(tmp_path):
    from lookalike.viz.video import VideoWriter

    mp4, gif = tmp_path / "robots.mp4", tmp_path / "robots.gif"
    mp4.write_bytes(b"earlier video")
    gif.write_bytes(b"earlier gif")
    frame = np.full((32, 48, 3), 200, np.uint8)
    with pytest.raises(KeyboardInterrupt):
        with VideoWriter(mp4, fps=10, gif=gif, atomic=True) as video:
            video.write(frame)
            video.write(frame)
            raise KeyboardInterrupt
    assert mp4.read_bytes() == b"earlier video" and gif.read_bytes() == b"earlier gif"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["robots.gif", "robots.mp4"]
    with VideoWriter(mp4, fps=10, gif=gif, atomic=True) as video:
        video.write(frame)
    assert mp4.read_bytes() != b"earlier video" and gif.read_bytes()[:3] == b"GIF"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["robots.gif", "robots.mp4"]


def test_a_gif_interrupted_while_saved_keeps_the_earlier_one(tmp_path, monkeypatch):
    from PIL import Image

    from lookalike.viz.video import write_gif

    gif = tmp_path / "robots.gif"
    gif.write_bytes(b"earlier gif")

    def interrupted(self, fp, *args, **kwargs):
        Path(fp).write_bytes(b"GIF89a, half")
        raise KeyboardInterrupt

    monkeypatch.setattr(Image.Image, "save", interrupted)
    with pytest.raises(KeyboardInterrupt):
        write_gif(gif, [np.zeros((8, 8, 3), np.uint8)] * 2, fps=5)
    assert gif.read_bytes() == b"earlier gif" and [p.name for p in tmp_path.iterdir()] == ["robots.gif"]


def test_an_interrupted_robot_scene_keeps_the_earlier_video(tmp_path):
    from lookalike.viz.robots_scene import run_robot_scene

    (tmp_path / "robots.mp4").write_bytes(b"earlier video")
    calls = []

    def advance():
        calls.append(1)
        if len(calls) == 12:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        run_robot_scene(tmp_path, preset_name="m3n2", frames=20, trackers=["kalman_ha2"], video_tracker="kalman_ha2",
                        render_width=64, scale=1, advance=advance)
    assert (tmp_path / "robots.mp4").read_bytes() == b"earlier video"
    assert not (tmp_path / "robots.gif").exists() and not list(tmp_path.glob(".*"))


def test_an_interrupted_merges_csv_leaves_the_earlier_file_whole(tmp_path):
    from lookalike.viz.video_tracking import write_merges_csv

    path = write_merges_csv(tmp_path / "res.merges.csv", [(3, 1, 2)])
    before = path.read_text()

    def rows():
        yield (4, 5, 6)
        raise KeyboardInterrupt  # Ctrl-C halfway through the rows

    with pytest.raises(KeyboardInterrupt):
        write_merges_csv(path, rows())
    assert path.read_text() == before and [p.name for p in tmp_path.iterdir()] == ["res.merges.csv"]


def test_an_interrupted_plot_leaves_the_earlier_png_whole(tmp_path, monkeypatch):
    from matplotlib.figure import Figure

    rows = [{"S": "a", "T": "x", "V": 50.0}, {"S": "b", "T": "x", "V": 10.0}]
    path = grouped_bar_chart(tmp_path / "g.png", rows, "S", "T", "V")
    before = path.read_bytes()

    def cut_short(self, fname, **kwargs):
        Path(fname).write_bytes(before[:100])  # part of a PNG, then Ctrl-C
        raise KeyboardInterrupt

    monkeypatch.setattr(Figure, "savefig", cut_short)
    with pytest.raises(KeyboardInterrupt):
        grouped_bar_chart(path, rows, "S", "T", "V")
    assert path.read_bytes() == before and [p.name for p in tmp_path.iterdir()] == ["g.png"]


def test_an_interrupted_still_leaves_the_earlier_png_whole(tmp_path, monkeypatch):
    """The demos' ``-still.png`` was written in place by ``cv2.imwrite``."""
    from lookalike.viz.video import write_png

    path = write_png(tmp_path / "robots-still.png", np.full((20, 30, 3), 200, np.uint8))
    before = path.read_bytes()
    assert cv2.imread(str(path)).shape == (20, 30, 3)

    def cut_short(self, data):
        Path.write_text(self, "half")  # part of the image, then Ctrl-C
        raise KeyboardInterrupt

    monkeypatch.setattr(Path, "write_bytes", cut_short)
    with pytest.raises(KeyboardInterrupt):
        write_png(path, np.zeros((20, 30, 3), np.uint8))
    monkeypatch.undo()
    assert path.read_bytes() == before and [p.name for p in tmp_path.iterdir()] == ["robots-still.png"]
