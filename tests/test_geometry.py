import numpy as np
from hypothesis import given
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from lookalike.geometry import (
    angle_diff,
    circular_mean,
    iou_matrix,
    wrap_angle,
    xysr_to_xywh,
    xywh_to_cxcywh,
    xywh_to_xysr,
    xywh_to_xyxy,
    xyxy_to_xywh,
)

boxes = arrays(
    float,
    st.tuples(st.integers(0, 6), st.just(4)),
    elements=st.floats(0.5, 500, allow_nan=False),
)


@given(boxes)
def test_box_round_trips(b):
    np.testing.assert_allclose(xyxy_to_xywh(xywh_to_xyxy(b)), b, atol=1e-9)
    np.testing.assert_allclose(xysr_to_xywh(xywh_to_xysr(b)), b, rtol=1e-9, atol=1e-7)


def test_conversions_known_values():
    b = np.array([[10.0, 20.0, 4.0, 8.0]])
    assert xywh_to_xyxy(b).tolist() == [[10, 20, 14, 28]]
    assert xywh_to_cxcywh(b).tolist() == [[12, 24, 4, 8]]
    assert xywh_to_xysr(b).tolist() == [[12, 24, 32, 0.5]]


def test_iou_known_values():
    a = np.array([[0, 0, 2, 2], [10, 10, 1, 1]], dtype=float)
    b = np.array([[1, 0, 2, 2], [0, 0, 2, 2], [0, 0, 0, 0]], dtype=float)
    iou = iou_matrix(a, b)
    # overlap 1x2=2, union 4+4-2=6
    np.testing.assert_allclose(iou[0], [2 / 6, 1.0, 0.0])
    np.testing.assert_allclose(iou[1], [0.0, 0.0, 0.0])
    assert iou_matrix(np.zeros((0, 4)), b).shape == (0, 3)


@given(boxes, boxes)
def test_iou_is_symmetric_and_bounded(a, b):
    m = iou_matrix(a, b)
    np.testing.assert_allclose(m, iou_matrix(b, a).T)
    assert np.all((m >= 0) & (m <= 1 + 1e-12))


def test_angles():
    assert wrap_angle(np.pi) == np.pi
    assert wrap_angle(-np.pi) == np.pi
    np.testing.assert_allclose(wrap_angle(3 * np.pi / 2), -np.pi / 2)
    np.testing.assert_allclose(angle_diff(np.pi - 0.1, -np.pi + 0.1), -0.2)
    np.testing.assert_allclose(circular_mean(np.array([np.pi - 0.1, -np.pi + 0.1])), np.pi)


@given(st.floats(-100, 100), st.floats(-100, 100))
def test_angle_diff_in_range(a, b):
    d = angle_diff(a, b)
    assert -np.pi < d <= np.pi
    np.testing.assert_allclose(np.cos(d), np.cos(a - b), atol=1e-9)
