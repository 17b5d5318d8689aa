"""Simulated runs as rosbag2 files (the ``ros`` extra): written, opened with rosbags' own reader, and read back into
the same identities as the run's ``.jsonl``, through an identifier and through the pixel pipeline."""

from __future__ import annotations

import math

import numpy as np
import pytest

pytest.importorskip("rosbags", reason="rosbag2 files need the 'ros' extra (rosbags)")

from lookalike.io.robot_sequences import read_robot_sequence, write_robot_sequence  # noqa: E402
from lookalike.io.rosbag import bag_images, bag_topics, read_bag, write_bag  # noqa: E402
from lookalike.io.rosmap import yaw  # noqa: E402
from lookalike.node.teamsim import team_sequence  # noqa: E402
from lookalike.trackers import make_tracker  # noqa: E402
from lookalike.trackers.parts.identity import labels_from_tracks  # noqa: E402

WARM_UP = 10  # frames


def _labels(sequence):
    tracker = make_tracker("set", n_agents=sequence.config.n_agents)
    return [labels_from_tracks(len(f.detections), tracker.update(f)).tolist() for f in sequence.frames()]


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    folder = tmp_path_factory.mktemp("bag")
    sequence = team_sequence("m5n3", 3, 3.0, loss=0.1)
    return sequence, write_robot_sequence(folder / "run.jsonl", sequence), write_bag(folder / "run", sequence)


def test_bag_gives_the_identities_of_the_jsonl(run):
    sequence, jsonl, bag = run
    from_jsonl, from_bag = read_robot_sequence(jsonl), read_bag(bag).sequence
    assert len(from_bag) == len(from_jsonl) == len(sequence)
    a, b = from_jsonl.arrays, from_bag.arrays
    assert np.array_equal(a.det_label, b.det_label) and np.array_equal(a.reports.frame_offsets, b.reports.frame_offsets)
    assert np.allclose(a.reports.t_sent, b.reports.t_sent, atol=1e-9)  # (stamps are whole nanoseconds)
    assert np.allclose(a.true_position, b.true_position) and from_bag.config == from_jsonl.config
    # Stamps are whole nanoseconds: frame times k/30 s move by < 1 ns, which can only break a tie between
    # assignments while the identifier has seen almost nothing (at most the first frames: WARM_UP).
    assert _labels(from_bag)[WARM_UP:] == _labels(from_jsonl)[WARM_UP:]


def test_bag_opens_in_rosbags_own_reader_with_ros_types(run):
    sequence, _, bag = run
    from rosbags.rosbag2 import Reader
    from rosbags.typesys import Stores, get_typestore

    with Reader(bag) as reader:
        kinds = {c.topic: c.msgtype for c in reader.connections}
        assert kinds == bag_topics(bag)
        assert kinds["/robot_0/imu"] == kinds["/robot_2/imu"] == "sensor_msgs/msg/Imu"
        assert kinds["/lookalike/detections"] == "vision_msgs/msg/Detection2DArray"
        assert kinds["/lookalike/truth"] == "geometry_msgs/msg/PoseArray"
        assert kinds["/observer/pose"] == "geometry_msgs/msg/PoseStamped"
        store = get_typestore(Stores.ROS2_HUMBLE)  # standard messages only: no lookalike definitions needed
        imu = [c for c in reader.connections if c.topic == "/robot_1/imu"]
        first = next(iter(reader.messages(connections=imu)))
        msg = store.deserialize_cdr(first[2], "sensor_msgs/msg/Imu")
    r = sequence.arrays.reports
    i = int(np.flatnonzero(r.agent_id == 1)[0])
    q = msg.orientation
    assert math.isclose(yaw(q.x, q.y, q.z, q.w), math.remainder(float(r.heading[i]), 2 * math.pi), abs_tol=1e-9)
    assert first[1] == round(float(r.t_received[i]) * 1e9)  # log time: when the observer received it


def test_bag_with_images_replays_through_the_pixel_pipeline(tmp_path):
    pytest.importorskip("cv2", reason="the pixel pipeline needs the 'vision' extra")
    from lookalike.pipeline.robots import identify_video, pixel_frames
    from lookalike.sim import preset, simulate_robots
    from lookalike.sim.robot_camera import identifier_settings, pixel_camera, world_for_camera
    from lookalike.vision.pipeline import PipelineConfig, RobotPipeline
    from lookalike.viz.robot_pixels import render_robot_frames

    camera = pixel_camera()
    sequence = simulate_robots(world_for_camera(preset("m3n2"), camera), 12, 3)
    images = [r.image for r in render_robot_frames(sequence, camera, 3)]
    bag = write_bag(tmp_path / "run", sequence, images)
    assert bag_topics(bag)["/camera/image_raw"] == "sensor_msgs/msg/Image"
    replay = read_bag(bag, camera_topic="/camera/image_raw")
    back = list(bag_images(bag))
    assert len(back) == len(images) and all(np.array_equal(x, y) for x, y in zip(back, images))

    def identify(frames, output):
        config = PipelineConfig(identifier="set", n_agents=sequence.config.n_agents,
                                max_detections=sequence.config.max_detections,
                                identifier_params=tuple(dict(identifier_settings("set", camera)).items()))
        identify_video(RobotPipeline.from_files(None, None, camera, config), frames, output)
        return output.read_text()

    direct = identify(pixel_frames(images, sequence), tmp_path / "direct.txt")
    assert identify(pixel_frames(back, replay.sequence), tmp_path / "bag.txt") == direct


def test_simulate_bag_writes_a_bag_beside_the_jsonl(tmp_path):
    from typer.testing import CliRunner

    from lookalike.cli import app

    args = ["simulate", "--preset", "m3n2", "--frames", "20", "--seed", "4", "--bag", "-o", str(tmp_path)]
    result = CliRunner().invoke(app, args)
    assert result.exit_code == 0, result.output
    bag, jsonl = tmp_path / "m3n2-000004", tmp_path / "m3n2-000004.jsonl"
    assert "(rosbag2)" in result.output and bag_topics(bag)["/robot_1/imu"] == "sensor_msgs/msg/Imu"
    assert np.array_equal(read_bag(bag).sequence.arrays.det_label, read_robot_sequence(jsonl).arrays.det_label)
    again = CliRunner().invoke(app, args)
    assert again.exit_code != 0 and "exists" in again.output  # never overwritten
    assert CliRunner().invoke(app, [*args[:-3], "--images", "-o", str(tmp_path / "x")]).exit_code != 0  # needs --bag


def test_track_bag_matches_track_video_on_the_same_frames(tmp_path):
    """``simulate --bag --images`` then ``track --bag``: the same rows as ``track --video`` on the same frames (as
    lossless PNGs) with the run's ``.jsonl`` as ``--reports``."""
    cv2 = pytest.importorskip("cv2", reason="the pixel pipeline needs the 'vision' extra")
    from typer.testing import CliRunner

    from lookalike.cli import app
    from lookalike.sim.robot_camera import pixel_camera
    from lookalike.viz.robot_pixels import render_robot_frames

    runner = CliRunner()
    made = runner.invoke(app, ["simulate", "--preset", "m3n2", "--frames", "12", "--seed", "4", "--bag", "--images",
                               "-o", str(tmp_path)])
    assert made.exit_code == 0, made.output
    jsonl, bag, pngs = tmp_path / "m3n2-000004.jsonl", tmp_path / "m3n2-000004", tmp_path / "frames"  # robot in view
    pngs.mkdir()
    for k, rendered in enumerate(render_robot_frames(read_robot_sequence(jsonl), pixel_camera(), 4)):
        cv2.imwrite(str(pngs / f"{k + 1:06d}.png"), rendered.image)
    from_bag = runner.invoke(app, ["track", "--bag", str(bag), "--camera-topic", "/camera/image_raw",
                                   "--heading-topics", "/robot_0/imu,/robot_1/imu", "-t", "set",
                                   "-o", str(tmp_path / "bag.txt")])
    assert from_bag.exit_code == 0, from_bag.output
    from_video = runner.invoke(app, ["track", "--video", str(pngs), "--pipeline", "robots", "--reports", str(jsonl),
                                     "-t", "set", "-o", str(tmp_path / "video.txt")])
    assert from_video.exit_code == 0, from_video.output
    rows = (tmp_path / "bag.txt").read_text()
    assert rows.strip() and rows == (tmp_path / "video.txt").read_text()
    refused = runner.invoke(app, ["track", "--bag", str(bag), "-t", "set", "-o", str(tmp_path / "x.txt")])
    assert refused.exit_code != 0 and "--camera-topic" in refused.output


def test_a_wrong_topic_type_or_no_bag_is_named(run):
    _, jsonl, bag = run
    with pytest.raises(ValueError, match="sensor_msgs/msg/Imu expected"):
        read_bag(bag, heading_topics=["/lookalike/detections"])
    with pytest.raises(ValueError, match="sensor_msgs/msg/Image expected"):
        read_bag(bag, camera_topic="/robot_0/imu")
    with pytest.raises(ValueError, match="sensor_msgs/msg/Image expected"):
        next(bag_images(bag, "/robot_0/imu"))
    for path in (jsonl, jsonl.parent / "missing"):
        with pytest.raises(ValueError, match="not a readable rosbag2 folder"):
            read_bag(path)
        with pytest.raises(ValueError, match="not a readable rosbag2 folder"):
            bag_topics(path)
