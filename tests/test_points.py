"""Point data as tracker input (io.points) and closed-set tracking of anonymous points."""

from pathlib import Path

import numpy as np
import pytest

from lookalike.eval import evaluate_points
from lookalike.io.points import (
    PointFrames,
    points_to_rows,
    read_id_points,
    read_points_csv,
    read_points_mot,
    rows_to_points,
    typical_spacing,
)
from lookalike.trackers.offline.closed_set import online_rows, track_closed_set


def test_read_points_csv_with_and_without_header(tmp_path: Path) -> None:
    a = tmp_path / "a.csv"
    a.write_text("frame,x,y\n1,10,20\n1,30,40\n3,5,6\n")
    pf = read_points_csv(a)
    assert len(pf) == 3 and pf.count == 3
    np.testing.assert_array_equal(pf.points[0], [[10, 20], [30, 40]])
    assert pf.points[1].shape == (0, 2)
    b = tmp_path / "b.csv"
    b.write_text("2,1.5,2.5,extra\n\n1,0,0\n")
    assert [len(p) for p in read_points_csv(b, n_frames=4).points] == [1, 1, 0, 0]


def test_read_points_mot_points_and_box_centres(tmp_path: Path) -> None:
    p = tmp_path / "det.txt"
    p.write_text("1,-1,10,20,4,6,1,-1,-1,-1\n2,-1,11,21,4,6,1,-1,-1,-1\n")
    np.testing.assert_array_equal(read_points_mot(p).points[0], [[10, 20]])
    np.testing.assert_array_equal(read_points_mot(p, centre=True).points[1], [[13, 24]])


@pytest.mark.parametrize("text, message", [
    ("frame,x,y\n1,2\n", ":2: expected at least 3"),
    ("1,2,3\n1,a,3\n", ":2: not a number"),
    ("1,2,3\n0,2,3\n", ":2: frame must be an integer >= 1, got '0' \\(a file is read as 0-based only when its first"),
    ("0,2,3\n-1,2,3\n", ":2: frame must be an integer >= 0, got '-1' \\(0-based frames"),
    ("1.5,2,3\n", ":1: frame must be"),
    ("1,nan,3\n", ":1: NaN"),
])
def test_bad_lines_name_file_and_line(tmp_path: Path, text: str, message: str) -> None:
    p = tmp_path / "bad.csv"
    p.write_text(text)
    with pytest.raises(ValueError, match=f"bad.csv{message}"):
        read_points_csv(p)


@pytest.mark.parametrize("text, message", [
    ("frame,id,x,y\n1,1,5,5\n2.7,1,6,5\n", ":3: frame must be an integer >= 1"),
    ("1,1,5,5\n2,1.5,6,5\n", ":2: invalid id: not a whole number"),
    ("1,1,5,5\n2,1e20,6,5\n", ":2: invalid id: beyond"),
    ("1,1,5,5\n2,1,nan,5\n", ":2: NaN"),
    ("1,1,5,5\n1000000000,1,6,5\n", ":2: invalid frame: frame 1000000000 jumps"),
    ("1,1,5,5\n2,1,1e300,5\n", ":2: a coordinate beyond"),
    ("1,1,5,5,-1,4,1,-1,-1,-1\n", ":1: invalid box"),
    ("frame,id,x,y\n1,1,5,5\n2,1,6,5\n1,2,9,9\n2,1,7,5\n", ":5: id 1 appears twice in frame 2 \\(line 3 too\\)"),
])
def test_eval_points_bad_lines_name_file_and_line(tmp_path: Path, text: str, message: str) -> None:
    """`eval --points` files keep the input rules: never a truncated frame or id, nor a run over a stray frame."""
    from typer.testing import CliRunner

    from lookalike.cli import app

    p = tmp_path / "bad.csv"
    p.write_text(text)
    with pytest.raises(ValueError, match=f"bad.csv{message}"):
        read_id_points(p)
    good = tmp_path / "gt.csv"
    good.write_text("frame,id,x,y\n1,1,5,5\n2,1,6,5\n")
    r = CliRunner().invoke(app, ["eval", "--points", "--gt", str(good), "--results", str(p), "--radius", "5"])
    assert r.exit_code == 2 and f"bad.csv:{message.split(':')[1]}:" in r.output, r.output


def test_eval_points_applies_metrics_and_refuses_box_options(tmp_path: Path) -> None:
    """--metrics restricts the files as for boxes; --iou-threshold and --benchmark, which points ignore, are refused."""
    from typer.testing import CliRunner

    from lookalike.cli import app

    gt = tmp_path / "gt.csv"
    gt.write_text("frame,id,x,y\n1,1,5,5\n2,1,6,5\n")
    args = ["eval", "--points", "--gt", str(gt), "--results", str(gt), "--radius", "5"]
    out = tmp_path / "s.csv"
    r = CliRunner().invoke(app, [*args, "--metrics", "Identity", "--csv", str(out)])
    assert r.exit_code == 0 and "points within 5 px" in r.output, r.output
    header = out.read_text().splitlines()[0].split(",")
    assert "IDF1" in header and not any(k.startswith(("HOTA", "MOTA", "CLR")) for k in header), header
    for extra in (["--iou-threshold", "0.7"], ["--benchmark", "MOT17"]):
        r = CliRunner().invoke(app, [*args, *extra])
        assert r.exit_code == 2 and "are for boxes" in r.output, r.output


HEXBUG = Path(__file__).resolve().parents[1].parent / "shared" / "data" / "hexbug" / "training01.csv"


def test_pandas_csv_with_named_columns_and_0_based_frames(tmp_path: Path) -> None:
    """A header's named columns are read wherever they are (an unnamed index column skipped); frame 0 on the first
    line makes the file 0-based, as for detection files. Was: refused at line 2, "frame must be >= 1, got '0'"."""
    p = tmp_path / "bugs.csv"
    p.write_text(",t,hexbug,x,y\n0,0,0,10.5,20\n1,0,1,30,40\n2,2,0,12,21\n")
    f, i, xy = read_id_points(p)
    assert f.tolist() == [1, 1, 3] and i.tolist() == [0, 1, 0] and xy.tolist() == [[10.5, 20], [30, 40], [12, 21]]
    pf = read_points_csv(p)
    assert [len(k) for k in pf.points] == [2, 0, 1] and pf.points[2].tolist() == [[12, 21]]
    q = tmp_path / "bugs.txt"
    q.write_text("y,x,frame\n1,2,1\n3,4,2\n")
    assert read_points_mot(q).points[1].tolist() == [[4, 3]]
    q.write_text("frame,x,y\n1,2,3\n")
    with pytest.raises(ValueError, match="bugs.txt:1: the header names no id column"):
        read_id_points(q)
    q.write_text("frame,px,py\n1,7,2,3\n")  # columns past the header's names are taken by their place
    assert read_points_mot(q).points[0].tolist() == [[2, 3]]
    q.write_text("frame,id,x,y,w,h,conf\n1,3,10,20,4,6,0.9\n")  # x, y beside a box size: a box's corner
    assert read_id_points(q)[2].tolist() == [[12, 23]]
    if HEXBUG.is_file():  # a real pandas-written file, copied
        real = tmp_path / "real.csv"
        real.write_bytes(HEXBUG.read_bytes())
        f, i, xy = read_id_points(real)
        assert f.min() == 1 and len(read_points_csv(real)) == f.max() and set(i.tolist()) <= {0, 1, 2, 3}


def test_track_points_says_it_read_a_0_based_file(tmp_path: Path) -> None:
    """As for a 0-based detection file, `track --points` notes the 0-based frames; the results are 1-based."""
    from typer.testing import CliRunner

    from lookalike.cli import app

    p, q, out = tmp_path / "p.csv", tmp_path / "q.csv", tmp_path / "out.txt"
    p.write_text("t,x,y\n0,1,1\n0,50,50\n1,2,1\n1,51,50\n")
    r = CliRunner().invoke(app, ["track", "--points", str(p), "-t", "boxtrack", "-o", str(out)])
    assert r.exit_code == 0 and "p.csv: frames start at 0: read as 0-based" in r.output, r.output
    assert {line.split(",")[0] for line in out.read_text().splitlines()} <= {"1", "2"}
    q.write_text("t,x,y\n1,1,1\n1,50,50\n2,2,1\n")
    r = CliRunner().invoke(app, ["track", "--points", str(q), "-t", "boxtrack", "-o", str(out)])
    assert r.exit_code == 0 and "0-based" not in r.output, r.output


def test_read_id_points_centres_boxes(tmp_path: Path) -> None:
    p = tmp_path / "res.txt"
    p.write_text("frame,id,x,y\n1,3,10,20\n")
    f, i, xy = read_id_points(p)
    assert f.tolist() == [1] and i.tolist() == [3] and xy.tolist() == [[10, 20]]
    p.write_text("1,3,10,20,4,6,0.9,-1,-1,-1\n")
    assert read_id_points(p)[2].tolist() == [[12, 23]]


def test_missing_file_and_short_n_frames(tmp_path: Path) -> None:
    with pytest.raises(FileNotFoundError):
        read_points_csv(tmp_path / "nope.csv")
    p = tmp_path / "p.csv"
    p.write_text("5,1,1\n")
    with pytest.raises(ValueError, match="past n_frames"):
        read_points_csv(p, n_frames=3)


def test_points_to_rows_and_back() -> None:
    pts = [np.array([[0.0, 0.0], [10.0, 0.0]]), np.zeros((0, 2)), np.array([[5.0, 5.0]])]
    assert typical_spacing(pts) == 10.0
    rows = points_to_rows(PointFrames(pts))
    assert rows.shape == (3, 10)
    np.testing.assert_allclose(rows[:, 4:6], 5.0)  # half the typical spacing
    frame, _, centre = rows_to_points(rows)
    np.testing.assert_array_equal(frame, [1, 1, 3])
    np.testing.assert_allclose(centre, [[0, 0], [10, 0], [5, 5]])
    with pytest.raises(ValueError, match="box_px"):
        points_to_rows(pts, box_px=0.0)


def simulate_arena(n: int = 5, frames: int = 300, size: float = 400.0, seed: int = 0):
    """``n`` identical points: correlated random walks bouncing off the walls, 1 px noise, 5% misses and
    0.1 false points per frame. Returns the per-frame points and ground truth ``(frame, id, x, y)``."""
    rng = np.random.default_rng(seed)
    pos = rng.uniform(50, size - 50, (n, 2))
    ang = rng.uniform(0, 2 * np.pi, n)
    speed = 3.0 * rng.uniform(0.5, 1.5, n)
    gt, pts = [], []
    for k in range(frames):
        ang += rng.normal(0, 0.3, n)
        pos = pos + np.column_stack([np.cos(ang), np.sin(ang)]) * (speed * rng.uniform(0, 2, n))[:, None]
        for d in range(2):
            out = (pos[:, d] < 0) | (pos[:, d] > size)
            pos[out, d] = np.clip(pos[out, d], 0, size)
            ang[out] += np.pi
        seen = rng.random(n) >= 0.05
        pts.append(np.vstack([pos[seen] + rng.normal(0, 1.0, (int(seen.sum()), 2)),
                              rng.uniform(0, size, (rng.poisson(0.1), 2))]))
        gt += [(k + 1, i + 1, *pos[i]) for i in range(n)]
    return pts, np.array(gt)


def test_closed_set_tracks_anonymous_points_better_than_online() -> None:
    pts, gt = simulate_arena(seed=1)
    det = points_to_rows(pts)
    scores = {}
    for name, rows in (("online", online_rows(det, 25.0, len(pts), max_targets=5)),
                       ("offline", track_closed_set(det, 5, 25.0, n_frames=len(pts)))):
        f, i, xy = rows_to_points(rows)
        scores[name] = evaluate_points(gt[:, 0].astype(int), gt[:, 1].astype(int), gt[:, 2:4], f, i, xy,
                                       radius=10.0, num_frames=len(pts))["IDF1"]
    assert scores["offline"] > 0.95
    assert scores["offline"] >= scores["online"]


def test_read_points_csv_takes_x_and_y_named_by_its_header(tmp_path: Path) -> None:
    # simulate --arena writes points.csv as frame,id,x,y: the id column was read as x and x as y
    p = tmp_path / "points.csv"
    p.write_text("frame,id,x,y\n1,7,10.5,20.5\n1,8,30,40\n2,7,11,21\n")
    pf = read_points_csv(p)
    np.testing.assert_array_equal(pf.points[0], [[10.5, 20.5], [30, 40]])
    np.testing.assert_array_equal(pf.points[1], [[11, 21]])
    q = tmp_path / "yx.csv"
    q.write_text("frame,y,x\n1,2,3\n")
    np.testing.assert_array_equal(read_points_csv(q).points[0], [[3, 2]])
    other = tmp_path / "points.txt"  # MOTChallenge-style rows, read as frame,id,x,y unless the header names x and y
    other.write_text("frame,x,y,area\n1,10.5,20.5,50\n1,30,40,55\n2,11,21,50\n")
    np.testing.assert_array_equal(read_points_mot(other).points[0], [[10.5, 20.5], [30, 40]])
    other.write_text("1,7,10.5,20.5\n")
    np.testing.assert_array_equal(read_points_mot(other).points[0], [[10.5, 20.5]])
    quoted = tmp_path / "quoted.csv"  # R's write.csv quotes the header: x was read from the id column, silently
    quoted.write_text('"frame","id","x","y"\n1,7,10.5,20.5\n1,8,30,40\n2,7,11,21\n')
    np.testing.assert_array_equal(read_points_csv(quoted).points[0], [[10.5, 20.5], [30, 40]])
