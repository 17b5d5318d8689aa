import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from lookalike.geometry import Camera, Extrinsics, Intrinsics, Pose2D, integrate_odometry


def _camera(pitch=0.4, roll=0.0, yaw=0.0, height=0.9):
    return Camera(Intrinsics.from_fov(640, 480, math.radians(70)), Extrinsics(height, pitch, roll, yaw))


def test_level_camera_known_projection():
    cam = Camera(Intrinsics(500.0, 500.0, 320.0, 240.0, 640, 480), Extrinsics(1.0, 0.0))
    # A point 1 m forward at camera height is the principal point; 1 m left and down by 0.5 m shift it.
    uv = cam.points_to_pixels(np.array([[2.0, 0.0, 1.0], [2.0, 1.0, 0.5]]))
    np.testing.assert_allclose(uv, [[320.0, 240.0], [320.0 - 250.0, 240.0 + 125.0]])
    # Ground point 2 m ahead: 1 m below the axis at 2 m depth -> v = 240 + 250.
    np.testing.assert_allclose(cam.ground_to_pixels(np.array([[2.0, 0.0]])), [[320.0, 490.0]])


def test_pitch_down_moves_horizon_up_and_principal_ray_hits_ground():
    h, pitch = 0.9, math.radians(30)
    cam = _camera(pitch=pitch, height=h)
    k = cam.intrinsics
    ground = cam.pixels_to_ground(np.array([[k.cx, k.cy]]))
    np.testing.assert_allclose(ground, [[h / math.tan(pitch), 0.0]], atol=1e-9)
    # Pixels above the horizon do not reach the ground.
    horizon_v = k.cy - k.fy * math.tan(pitch)
    assert np.isnan(cam.pixels_to_ground(np.array([[k.cx, horizon_v - 5.0]]))).all()
    assert np.isfinite(cam.pixels_to_ground(np.array([[k.cx, horizon_v + 5.0]]))).all()


def test_positive_yaw_looks_left():
    cam = _camera(pitch=0.3, yaw=math.radians(40))
    k = cam.intrinsics
    p = cam.pixels_to_ground(np.array([[k.cx, k.cy]]))[0]
    assert math.isclose(math.atan2(p[1], p[0]), math.radians(40), abs_tol=1e-9)


positions = st.tuples(st.floats(0.8, 6.0), st.floats(-2.0, 2.0))


@settings(max_examples=60, deadline=None)
@given(
    st.lists(positions, min_size=1, max_size=5),
    st.floats(0.1, 0.7),
    st.floats(-0.2, 0.2),
    st.floats(-0.3, 0.3),
    st.floats(0.3, 2.0),
)
def test_ground_round_trip(points, pitch, roll, yaw, height):
    cam = _camera(pitch, roll, yaw, height)
    xy = np.array(points)
    uv = cam.ground_to_pixels(xy)
    back = cam.pixels_to_ground(uv)
    ok = np.isfinite(uv).all(axis=1)
    np.testing.assert_allclose(back[ok], xy[ok], rtol=1e-7, atol=1e-7)


@settings(max_examples=40, deadline=None)
@given(st.lists(positions, min_size=1, max_size=5), st.floats(0.2, 0.6), st.floats(-0.4, 0.4))
def test_box_round_trip(points, pitch, yaw):
    cam = _camera(pitch=pitch, yaw=yaw)
    xy = np.array(points)
    boxes = cam.ground_to_box(xy, height_m=0.6, width_m=0.3)
    ok = np.isfinite(boxes).all(axis=1)
    assert (boxes[ok, 2:] > 0).all()
    np.testing.assert_allclose(cam.box_to_ground(boxes[ok]), xy[ok], atol=1e-7)


def test_boxes_shrink_with_distance():
    cam = _camera(pitch=0.35)
    boxes = cam.ground_to_box(np.array([[1.0, 0.0], [2.0, 0.0], [4.0, 0.0]]), 0.6, 0.3)
    assert (np.diff(boxes[:, 3]) < 0).all() and (np.diff(boxes[:, 2]) < 0).all()
    # Width at 2 m ~ f * 0.3 / depth.
    depth = cam.depth_m(np.array([[2.0, 0.0, 0.3]]))[0]
    assert math.isclose(boxes[1, 2], cam.intrinsics.fx * 0.3 / depth, rel_tol=0.05)


def test_points_behind_camera_are_nan():
    cam = _camera(pitch=0.0)
    assert np.isnan(cam.points_to_pixels(np.array([[-1.0, 0.0, 0.5]]))).all()


def test_bad_inputs_are_refused():
    with pytest.raises(ValueError, match="Intrinsics.fx"):
        Intrinsics(0.0, 1.0, 0.0, 0.0, 10, 10)
    with pytest.raises(ValueError, match="Intrinsics.width"):
        Intrinsics(1.0, 1.0, 0.0, 0.0, 10.5, 10)
    with pytest.raises(ValueError, match="Extrinsics.height_m"):
        Extrinsics(-1.0)
    with pytest.raises(ValueError, match="pitch_rad"):
        Extrinsics(1.0, math.pi / 2)
    with pytest.raises(ValueError, match="xywh"):
        _camera().box_to_ground(np.zeros((2, 3)))
    with pytest.raises(ValueError, match="hfov_rad"):
        Intrinsics.from_fov(640, 480, 4.0)


def test_empty_batches():
    cam = _camera()
    assert cam.box_to_ground(np.zeros((0, 4))).shape == (0, 2)
    assert cam.ground_to_pixels(np.zeros((0, 2))).shape == (0, 2)


@settings(max_examples=50, deadline=None)
@given(st.floats(-5, 5), st.floats(-5, 5), st.floats(-3.1, 3.1), st.lists(positions, min_size=1, max_size=4))
def test_odometry_round_trip(x, y, theta, points):
    pose = Pose2D(x, y, theta)
    xy = np.array(points)
    np.testing.assert_allclose(pose.fixed_to_ego(pose.ego_to_fixed(xy)), xy, atol=1e-9)
    h = np.array([0.1, -2.0, 3.0])
    back = pose.heading_to_ego(pose.heading_to_fixed(h))
    np.testing.assert_allclose(np.angle(np.exp(1j * (back - h))), 0.0, atol=1e-9)


def test_odometry_integration_square_returns_home():
    # Four steps of 1 m forward then a 90° left turn trace a square back to the start.
    steps = np.tile([1.0, 0.0, math.pi / 2], (4, 1))
    poses = integrate_odometry(steps)
    assert len(poses) == 5
    np.testing.assert_allclose([poses[1].x_m, poses[1].y_m], [1.0, 0.0], atol=1e-12)
    np.testing.assert_allclose([poses[2].x_m, poses[2].y_m], [1.0, 1.0], atol=1e-12)
    end = poses[-1]
    np.testing.assert_allclose([end.x_m, end.y_m], [0.0, 0.0], atol=1e-12)
    assert abs(math.sin(end.heading_rad)) < 1e-12 and math.cos(end.heading_rad) > 0


def test_fixed_target_seen_from_moving_observer_stays_put():
    target = np.array([[3.0, 1.0]])
    steps = np.array([[0.5, 0.0, 0.2], [0.3, 0.1, -0.5], [0.0, 0.0, 1.0]])
    for pose in integrate_odometry(steps, Pose2D(0.2, -0.1, 0.3)):
        ego = pose.fixed_to_ego(target)
        np.testing.assert_allclose(pose.ego_to_fixed(ego), target, atol=1e-12)
    a, b = Pose2D(1.0, 2.0, 0.5), Pose2D(-1.0, 0.5, 2.9)
    step = b.relative_to(a)
    c = a.compose(*step)
    np.testing.assert_allclose([c.x_m, c.y_m, c.heading_rad], [b.x_m, b.y_m, b.heading_rad], atol=1e-12)
