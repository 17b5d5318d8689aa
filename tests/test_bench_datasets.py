"""lookalike.bench datasets and presets: HexBug orientation from the frame bounds, the data folder,
preset files that say what they were chosen on."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from lookalike.bench.datasets import hexbug_clips, points_swapped, read_hexbug_points, resolve_data_root
from lookalike.bench.presets import SEQUENCE_PARAMS, TUNED_PARAMS, chosen_on, load_preset

DATA = Path(__file__).resolve().parents[1].parent / "shared" / "data"


def _csv(path: Path, xy: np.ndarray) -> Path:
    lines = [",t,hexbug,x,y"] + [f"{k},{k % 3},{k % 2},{x},{y}" for k, (x, y) in enumerate(xy)]
    path.write_text("\n".join(lines) + "\n")
    return path


def test_points_outside_the_image_as_xy_but_inside_as_yx_are_swapped():
    size = (1080, 1500)  # width, height: a tall frame
    xy = np.array([[100.0, 1400.0], [900.0, 1200.0], [500.0, 300.0]])  # all inside as (x, y)
    assert not points_swapped(xy, size)
    assert points_swapped(xy[:, ::-1], size)  # stored (y, x): x up to 1400 > width
    assert not points_swapped(xy[:, ::-1], None)  # no frame size: as written
    inside_both = np.array([[100.0, 200.0], [300.0, 400.0]])
    assert not points_swapped(inside_both, size) and not points_swapped(inside_both[:, ::-1], size)


def test_read_hexbug_points_turns_a_yx_file_into_xy(tmp_path):
    xy = np.array([[100.0, 1400.0], [900.0, 1200.0], [500.0, 300.0]])
    frame, ids, got = read_hexbug_points(_csv(tmp_path / "yx.csv", xy[:, ::-1]), (1080, 1500))
    assert np.array_equal(got, xy) and frame.tolist() == [1, 2, 3]
    _, _, same = read_hexbug_points(_csv(tmp_path / "xy.csv", xy), (1080, 1500))
    assert np.array_equal(same, xy)


@pytest.mark.skipif(not (DATA / "hexbug").is_dir(), reason="../shared/data/hexbug is absent")
def test_hexbug_clips_with_videos_keep_their_written_order():
    cv2 = pytest.importorskip("cv2", reason="OpenCV is not installed")
    for video in hexbug_clips(DATA / "hexbug"):
        cap = cv2.VideoCapture(str(video))
        size = (int(cap.get(cv2.CAP_PROP_FRAME_WIDTH)), int(cap.get(cv2.CAP_PROP_FRAME_HEIGHT)))
        cap.release()
        _, _, xy = read_hexbug_points(video.with_suffix(".csv"))
        assert not points_swapped(xy, size), video.name
        assert ((xy >= 0) & (xy < size)).all(), video.name  # every head inside the frame


def test_data_root_from_option_env_or_shared_data(tmp_path, monkeypatch):
    monkeypatch.delenv("LOOKALIKE_DATA", raising=False)
    assert resolve_data_root(tmp_path) == tmp_path
    monkeypatch.setenv("LOOKALIKE_DATA", str(tmp_path))
    assert resolve_data_root() == tmp_path
    monkeypatch.delenv("LOOKALIKE_DATA")
    work = tmp_path / "repo"
    work.mkdir()
    (tmp_path / "shared" / "data").mkdir(parents=True)
    monkeypatch.chdir(work)
    assert resolve_data_root() == tmp_path / "shared" / "data"
    with pytest.raises(FileNotFoundError, match="--data") as err:
        resolve_data_root(tmp_path / "nowhere")
    assert "nowhere" in str(err.value)
    monkeypatch.setenv("LOOKALIKE_DATA", str(tmp_path / "gone"))
    with pytest.raises(FileNotFoundError, match="LOOKALIKE_DATA"):
        resolve_data_root()


def test_presets_say_what_they_were_chosen_on():
    preset = load_preset("boxtrack")
    assert set(preset) == {"tracker", "about", "sequences", "tuned"}  # no group applied to a headline row
    for group in ("sequences", "tuned"):
        for dataset, entry in preset[group].items():
            assert entry["chosen_on"] and entry["params"] and entry["label"] == "tuned on this data", dataset
    assert TUNED_PARAMS["pigs"]["boxtrack"] == {"high_score": 0.7, "birth_score": 0.7}
    assert "report" not in SEQUENCE_PARAMS["mot15"]["boxtrack"]["KITTI-13"]  # a constant of boxtrack since issue 16
    assert SEQUENCE_PARAMS["mot15"]["boxtrack"]["ADL-Rundle-6"]["clutter_factor"] is None
    assert "first half" in chosen_on("boxtrack", "mot15") and chosen_on("boxtrack", "nothing") == ""
