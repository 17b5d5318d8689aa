import numpy as np
import pytest

from lookalike.geometry import Camera, Pose2D
from lookalike.geometry.angles import wrap_angle
from lookalike.sim.render_robots import ROBOT_HEIGHT_M, ROBOT_WIDTH_M, RobotRenderer


def random_walk_poses(
    n_frames: int, n_robots: int, seed: int, field_m: tuple[float, float] = (9.0, 6.0), dt_s: float = 0.1
) -> tuple[np.ndarray, np.ndarray]:
    """Bounded random motion on the field: fixed-frame positions ``(T, N, 2)`` (m) and headings ``(T, N)`` (rad)."""
    if n_frames < 1 or n_robots < 0:
        raise ValueError(f"n_frames/n_robots: need n_frames >= 1 and n_robots >= 0, got {n_frames}, {n_robots}")
    rng = np.random.default_rng(seed)
    half = 0.5 * np.array(field_m) - 0.3
    pos = rng.uniform(-half, half, (n_robots, 2))
    head = rng.uniform(-np.pi, np.pi, n_robots)
    vel = np.zeros((n_robots, 2))
    omega = np.zeros(n_robots)
    out_p = np.empty((n_frames, n_robots, 2))
    out_h = np.empty((n_frames, n_robots))
    for t in range(n_frames):
        out_p[t], out_h[t] = pos, head
        vel = np.clip(vel + rng.normal(0.0, 0.6, vel.shape) * dt_s, -0.4, 0.4)
        omega = np.clip(omega + rng.normal(0.0, 3.0, n_robots) * dt_s, -1.5, 1.5)
        pos = pos + vel * dt_s
        bounce = np.abs(pos) > half
        vel[bounce] *= -1.0
        pos = np.clip(pos, -half, half)
        head = np.asarray(wrap_angle(head + omega * dt_s))
    return out_p, out_h


def test_deterministic_by_seed_and_boxes_match_camera():
    pos = np.array([[2.0, 0.3], [3.5, -0.8]])
    head = np.array([0.3, -2.0])
    a = RobotRenderer(seed=3).render(pos, head)
    b = RobotRenderer(seed=3).render(pos, head)
    c = RobotRenderer(seed=4).render(pos, head)
    assert np.array_equal(a.image, b.image) and not np.array_equal(a.image, c.image)
    assert a.robot_id.tolist() == [0, 1]
    np.testing.assert_allclose(a.visible, 1.0, atol=0.02)
    # The rendered box's bottom-centre projects back near the robot's position (the nearest edge of
    # the feet is a few cm in front of the centre, which shifts the estimate by a few % of the range).
    back = Camera.default().box_to_ground(a.xywh)
    err = np.linalg.norm(back - pos, axis=1)
    assert (err < 0.05 * np.linalg.norm(pos, axis=1) + 0.02).all(), err
    expected = Camera.default().ground_to_box(pos, ROBOT_HEIGHT_M, ROBOT_WIDTH_M)
    np.testing.assert_allclose(a.xywh[:, 3], expected[:, 3], rtol=0.1)


def test_torso_appearance_depends_on_heading():
    r = RobotRenderer(seed=0)
    front = r.render(np.array([[2.0, 0.0]]), np.array([np.pi]))  # facing the camera: orange chest
    back = r.render(np.array([[2.0, 0.0]]), np.array([0.0]))  # facing away: dark backpack
    def orange(f):
        x, y, w, h = f.xywh[0].astype(int)
        crop = f.image[y : y + h // 2, x : x + w].astype(int)
        return ((crop[..., 2] > crop[..., 1] + 30) & (crop[..., 2] > crop[..., 0] + 60)).mean()
    assert orange(front) > 0.05 and orange(back) < 0.01
    np.testing.assert_allclose(front.heading_rad, [np.pi])


def test_occlusion_border_and_out_of_view():
    r = RobotRenderer(seed=1)
    f = r.render(np.array([[2.0, 0.0], [3.0, 0.0], [-2.0, 0.0], [1.2, 1.1]]), np.zeros(4))
    ids = f.robot_id.tolist()
    assert 2 not in ids  # behind the observer
    vis = dict(zip(ids, f.visible))
    assert vis[0] > 0.95 and vis[1] < 0.6  # the far robot is hidden behind the near one
    assert vis[3] < 0.9 and f.xywh[ids.index(3)][0] == 0  # cut by the left image border


def test_observer_pose_moves_the_view():
    pos, head = np.array([[3.0, 1.0]]), np.array([1.0])
    obs = Pose2D(1.0, 1.0, 0.0)
    f = RobotRenderer(seed=0).render(pos, head, obs)
    np.testing.assert_allclose(f.position_m, [[2.0, 0.0]])
    np.testing.assert_allclose(f.heading_rad, [1.0])


def test_random_walk_and_bad_input():
    p, h = random_walk_poses(50, 3, seed=2)
    assert p.shape == (50, 3, 2) and h.shape == (50, 3)
    assert (np.abs(p[..., 0]) <= 4.5).all() and (np.abs(p[..., 1]) <= 3.0).all()
    assert np.array_equal(p, random_walk_poses(50, 3, seed=2)[0])
    with pytest.raises(ValueError, match="headings_rad"):
        RobotRenderer().render(np.zeros((2, 2)), np.zeros(3))
    empty = RobotRenderer().render(np.zeros((0, 2)), np.zeros(0))
    assert empty.image.shape == (480, 640, 3) and len(empty.robot_id) == 0
