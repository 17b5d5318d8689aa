import numpy as np
import pytest

from lookalike import Beacons, Detections, Frame, TrackSnapshot, TrackStatus


def test_detections_valid_and_readonly():
    det = Detections(xywh=[[0, 0, 10, 20], [5, 5, 1, 1]], score=[0.9, 0.5], heading=[0.1, -3.0])
    assert len(det) == 2
    assert det.xywh.shape == (2, 4)
    with pytest.raises(ValueError):
        det.xywh[0, 0] = 3.0  # read-only


def test_empty_is_valid_everywhere():
    assert len(Detections.empty()) == 0
    assert len(Detections(xywh=np.zeros((0, 4)))) == 0
    assert len(Detections(xywh=[])) == 0
    assert len(Beacons.empty()) == 0
    frame = Frame(index=0, time=0.0)
    assert len(frame.detections) == 0 and len(frame.beacons) == 0


@pytest.mark.parametrize(
    "kwargs, message",
    [
        ({"xywh": [[0, 0, 1, 1], [0, np.nan, 1, 1]]}, "xywh: row 1"),
        ({"xywh": [[0, 0, 1, 1], [0, 0, np.inf, 1]]}, "xywh: row 1"),
        ({"xywh": [[0, 0, 1, 1], [0, 0, 1, -2]]}, "xywh: row 1 has a negative"),
        ({"xywh": [[0, 0, 1, 1]], "score": [0.5, 0.5]}, "score: has 2 rows"),
        ({"xywh": [[0, 0, 1]]}, "xywh: expected shape (n, 4)"),
        ({"xywh": [[0, 0, 1, 1]], "position": [[np.nan, 0]]}, "position: row 0"),
        ({"xywh": [[0, 0, 1, 1]], "heading": [np.nan]}, "heading: row 0"),
        ({"xywh": [[0, 0, 1, 1]] * 2, "feature": np.zeros((2, 0))}, "feature: 2 rows of length 0"),  # (not "0 rows")
        ({"xywh": [[0, 0, 1, 1]] * 2, "feature": np.zeros((0, 8))}, "feature: has 0 rows"),
    ],
)
def test_detections_reject_bad_columns(kwargs, message):
    with pytest.raises(ValueError, match=message.replace("(", r"\(").replace(")", r"\)")):
        Detections(**kwargs)


def test_unknown_fields_are_named():
    with pytest.raises(ValueError, match="unknown field.*'colour'"):
        Detections.from_dict({"xywh": [[0, 0, 1, 1]], "colour": [1]})
    with pytest.raises(ValueError, match="unknown field.*'speed'"):
        Beacons.from_dict({"agent_id": [0], "t_sent": [0], "t_received": [0], "heading": [0], "speed": [1]})


def test_world_only_detections_get_zero_boxes():
    det = Detections(position=[[1.0, 2.0], [3.0, 4.0]])
    assert det.xywh.shape == (2, 4) and not det.xywh.any()
    assert np.all(det.score == 1.0)


def test_select_keeps_columns_together():
    det = Detections(xywh=[[0, 0, 1, 1], [1, 1, 2, 2], [3, 3, 1, 1]], label=[4, 5, 6])
    sub = det.select(np.array([True, False, True]))
    assert sub.label.tolist() == [4, 6]
    assert sub.xywh[:, 0].tolist() == [0, 3]


def test_beacons_validate():
    with pytest.raises(ValueError, match="agent_id: row 0 is negative"):
        Beacons(agent_id=[-1], t_sent=[0], t_received=[0], heading=[0])
    with pytest.raises(ValueError, match="heading: has 1 rows but the batch has 2"):
        Beacons(agent_id=[0, 1], t_sent=[0, 0], t_received=[0, 0], heading=[0])
    with pytest.raises(ValueError, match="t_received: row 0"):
        Beacons(agent_id=[0], t_sent=[0], t_received=[np.nan], heading=[0])


def test_frame_validates():
    with pytest.raises(ValueError, match="Frame.index"):
        Frame(index=-1, time=0.0)
    with pytest.raises(ValueError, match="Frame.time"):
        Frame(index=0, time=float("nan"))
    with pytest.raises(ValueError, match="Frame.detections"):
        Frame(index=0, time=0.0, detections=[[0, 0, 1, 1]])  # type: ignore[arg-type]


def test_track_snapshot_is_frozen():
    snap = TrackSnapshot(track_id=1, status=TrackStatus.CONFIRMED, xywh=np.zeros(4))
    with pytest.raises(AttributeError):
        snap.track_id = 2  # type: ignore[misc]


def test_tracks_batch_reads_like_a_list_of_snapshots_and_writes_rows() -> None:
    from lookalike.types import Tracks, TrackSnapshot, TrackStatus

    boxes = np.array([[1.0, 2.0, 3.0, 4.0], [5.0, 6.0, 7.0, 8.0]])
    tracks = Tracks(np.array([7, 9]), np.array([1, 0]), xywh=boxes, velocity=np.zeros((2, 2)),
                    detection_index=np.array([0, -1]))
    assert len(tracks) == 2 and bool(tracks) and tracks != [] and Tracks.empty() == []
    first = tracks[0]
    assert isinstance(first, TrackSnapshot) and first.track_id == 7 and first.status is TrackStatus.CONFIRMED
    assert [t.track_id for t in tracks] == [7, 9] and tracks[-1].status is TrackStatus.TENTATIVE
    assert tracks[1].detection_index == -1 and tracks[0].heading is None and tracks[0].agent_id is None
    assert [t.track_id for t in tracks[:1]] == [7] and tracks.statuses()[1] is TrackStatus.TENTATIVE
    rows = tracks.to_rows(4)
    assert rows.shape == (2, 10) and rows[:, 0].tolist() == [5, 5] and rows[:, 1].tolist() == [7, 9]
    np.testing.assert_array_equal(rows[:, 2:6], boxes)
    assert rows[:, 6].tolist() == [1.0, 1.0] and (rows[:, 7:] == -1).all()
    world = Tracks(np.array([1]), TrackStatus.LOST, position=np.array([[1.0, 2.0]]), heading=np.array([np.nan]),
                   agent_id=np.array([2]), identity_prob=np.array([0.8]))
    snap = world[0]
    assert snap.xywh is None and snap.agent_id == 2 and snap.identity_prob == 0.8 and snap.status is TrackStatus.LOST
    assert world.to_rows(0).shape == (0, 10)
    back = Tracks.from_snapshots(list(tracks))
    np.testing.assert_array_equal(back.to_rows(4), rows)
    with pytest.raises(IndexError):
        tracks[2]
    with pytest.raises(ValueError):
        Tracks(np.array([1, 2]), TrackStatus.CONFIRMED, xywh=np.zeros((1, 4)))


def test_tracks_columns_of_another_length_or_status_code_are_named() -> None:
    from lookalike.types import Tracks

    # a numpy reshape error that named no column, or (status 5) an IndexError when the statuses were read
    with pytest.raises(ValueError, match="Tracks.status: has 1 values but the batch has 2"):
        Tracks(np.array([1, 2]), np.array([0]), xywh=np.zeros((2, 4)))
    with pytest.raises(ValueError, match="Tracks.detection_index: has 3 values"):
        Tracks(np.array([1, 2]), np.array([0, 1]), detection_index=np.array([0, 1, 2]))
    with pytest.raises(ValueError, match=r"Tracks.status: codes are 0 .* got \[1, 5\]"):
        Tracks(np.array([1, 2]), np.array([1, 5]))
    assert Tracks(np.array([[3]]), [2]).statuses()[0].value == "lost"


def test_tracks_refuse_boxes_of_another_width_and_fractional_ids() -> None:
    from lookalike.types import Tracks

    # boxes of 3 numbers failed only when written (a numpy broadcast error); id 1.7 was truncated to 1
    with pytest.raises(ValueError, match=r"Tracks.xywh: rows of 4 numbers expected, got shape \(2, 3\)"):
        Tracks(np.array([1, 2]), np.array([1, 1]), xywh=np.zeros((2, 3)))
    with pytest.raises(ValueError, match=r"Tracks.position: rows of 2 numbers expected, got shape \(1, 3\)"):
        Tracks(np.array([1]), np.array([1]), position=np.zeros((1, 3)))
    with pytest.raises(ValueError, match=r"Tracks.id: row 1 is not a whole number \(.*1.7\)"):
        Tracks(np.array([1.0, 1.7]), np.array([1, 1]))
    assert Tracks(np.array([1.0, 2.0]), np.array([1, 1]), xywh=[[0, 0, 1, 1]] * 2).to_rows(0)[:, 1].tolist() == [1, 2]


@pytest.mark.parametrize("index, time, field", [("a", 0.0, "Frame.index"), (None, 0.0, "Frame.index"),
                                                (0, None, "Frame.time"), (0, "soon", "Frame.time")])
def test_frame_names_an_index_or_time_that_is_no_number(index, time, field) -> None:
    # a TypeError from float(None), or int()'s "invalid literal" naming no field
    with pytest.raises(ValueError, match=field):
        Frame(index=index, time=time)
