"""What boxtrack gets on blob detections: one rule for ``lookalike track --detector blob`` and the benches."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pytest
from typer.testing import CliRunner

from lookalike.bench.datasets import RealSequence
from lookalike.bench.runner import Entry, blob_tracker_config, track_rows
from lookalike.cli import app
from lookalike.io import MotTable, read_mot
from lookalike.trackers.boxtrack_config import BoxTrackConfig
from lookalike.vision.blob_auto import BOX_TRACKER_PARAMS
from lookalike.vision.blob_boxtrack import blob_boxtrack_config

THREE = np.full(40, 3)


def test_blob_params_replace_only_what_the_user_did_not_give() -> None:
    assert blob_boxtrack_config(BoxTrackConfig(), THREE).config.match_iou == BOX_TRACKER_PARAMS["match_iou"]
    # an explicit match_iou equal to the default is kept: decided by the keys given, not by the value
    kept = blob_boxtrack_config(BoxTrackConfig(match_iou=0.3), THREE, {"match_iou"})
    assert kept.config.match_iou == 0.3
    assert blob_boxtrack_config(BoxTrackConfig(match_iou=0.5), THREE, ["match_iou"]).config.match_iou == 0.5


def test_blob_target_count_inferred_given_or_open() -> None:
    inferred = blob_boxtrack_config(BoxTrackConfig(), THREE)
    assert inferred.n_targets == 3 and inferred.config.max_targets == 3 and inferred.count is not None
    varying = blob_boxtrack_config(BoxTrackConfig(), np.repeat([1, 2, 3], 10))
    assert varying.n_targets is None and varying.count is not None and not varying.count.closed
    given = blob_boxtrack_config(BoxTrackConfig(max_targets=2), THREE, {"max_targets"})
    assert given.n_targets == 2 and given.count is None
    assert blob_boxtrack_config(BoxTrackConfig(), THREE, n_targets=0).n_targets is None  # --targets 0


def _video(path: Path, frames: int = 30) -> Path:
    import cv2

    writer = cv2.VideoWriter(str(path), cv2.VideoWriter_fourcc(*"MJPG"), 10, (160, 120))
    assert writer.isOpened()
    for k in range(frames):
        img = np.full((120, 160, 3), 215, np.uint8)
        for x, y, vx in ((20, 20, 3), (140, 60, -3), (30, 100, 2)):
            cv2.circle(img, (x + vx * k, y), 7, (35, 35, 35), -1)
        writer.write(img)
    writer.release()
    return path


def _sequence(det: MotTable, length: int) -> RealSequence:
    xywh = [det.xywh[det.frame == k + 1] for k in range(length)]
    score = [det.conf[det.frame == k + 1] for k in range(length)]
    return RealSequence("hexbug", "discs", 10.0, length, xywh, score,
                        gt_points=(np.ones(1), np.ones(1), np.ones((1, 2))))


@pytest.mark.parametrize("settings", [[], ["match_iou=0.3"], ["match_iou=0.3", "max_targets=2"]])
def test_cli_and_bench_give_the_same_config(tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
                                            settings: list[str]) -> None:
    """The tracker the CLI runs on a blob video is the one the bench runs on the same blob rows, with the
    same explicit parameters (``--set`` there, an entry's parameters here)."""
    monkeypatch.setenv("LOOKALIKE_CACHE", str(tmp_path / "cache"))
    ran: dict[str, Any] = {}

    def capture(video: Path, det: Path, output: Path, tracker: Any, name: str, *args: Any, **options: Any) -> Any:
        from lookalike.pipeline import RunResult

        ran["config"] = tracker.config
        return RunResult("video")

    monkeypatch.setattr("lookalike.pipeline.video.run_video", capture)
    out = tmp_path / "tracks.txt"
    args = ["track", "--video", str(_video(tmp_path / "discs.avi")), "--detector", "blob", "-t", "boxtrack",
            "-o", str(out), "--save-detections", str(tmp_path / "tracks.det.txt")]
    for s in settings:
        args += ["--set", s]
    result = CliRunner().invoke(app, args)
    assert result.exit_code == 0, result.output
    det = read_mot(tmp_path / "tracks.det.txt")
    params: dict[str, Any] = {k: float(v) if "." in v else int(v) for k, v in (s.split("=") for s in settings)}
    bench = blob_tracker_config(BoxTrackConfig(**params), _sequence(det, 30), params)
    assert ran["config"] == bench
    assert bench.match_iou == (0.3 if settings else BOX_TRACKER_PARAMS["match_iou"])
    assert bench.max_targets == (2 if len(settings) == 2 else 3)


def test_bench_tracks_blob_datasets_with_the_blob_rule(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """track_rows on a blob dataset builds its boxtrack through the shared rule."""
    seen: list[BoxTrackConfig] = []
    import lookalike.bench.runner as runner

    real = runner.blob_tracker_config

    def spy(config: BoxTrackConfig, seq: RealSequence, params: dict[str, Any]) -> BoxTrackConfig:
        seen.append(out := real(config, seq, params))
        return out

    monkeypatch.setattr(runner, "blob_tracker_config", spy)
    length = 20
    xywh = [np.array([[10.0 + 3 * k, 10, 12, 12], [100.0 - 3 * k, 60, 12, 12]]) for k in range(length)]
    seq = RealSequence("hexbug", "two", 10.0, length, xywh, [np.ones(2)] * length,
                       gt_points=(np.ones(1), np.ones(1), np.ones((1, 2))))
    rows = track_rows(Entry("boxtrack", "boxtrack", params={"n_init": 2}), seq)
    assert len(np.unique(rows[:, 1])) == 2
    assert seen and seen[0].max_targets == 2 and seen[0].match_iou == BOX_TRACKER_PARAMS["match_iou"]
    assert seen[0].n_init == 2
