"""``Tracks``: the tracks a tracker reports for one frame, as columns; ``TrackSnapshot``: the
immutable state of one track (a row of ``Tracks``); ``TrackStatus``: its lifecycle status."""

from __future__ import annotations

import enum
from collections.abc import Iterator, Sequence
from dataclasses import dataclass
from typing import overload

import numpy as np

from lookalike.types._validate import first_fraction


class TrackStatus(enum.Enum):
    """Lifecycle of a track."""

    TENTATIVE = "tentative"
    CONFIRMED = "confirmed"
    LOST = "lost"


@dataclass(frozen=True, eq=False)
class TrackSnapshot:
    """A track as output by a tracker for one frame.

    Attributes:
        track_id: 1-based id, unique within one tracker run.
        status: lifecycle status.
        xywh: ``(4,)`` box in pixels, or None for world-only trackers.
        position: ``(2,)`` ground position in metres, or None.
        velocity: velocity of the state (pixels/s or metres/s), or None.
        heading: absolute heading in radians, or None.
        agent_id: identified agent (0-based), or None.
        identity_prob: confidence of ``agent_id`` in [0, 1], or None.
        detection_index: index of the detection that updated the track this frame, or -1."""

    track_id: int
    status: TrackStatus
    xywh: np.ndarray | None = None
    position: np.ndarray | None = None
    velocity: np.ndarray | None = None
    heading: float | None = None
    agent_id: int | None = None
    identity_prob: float | None = None
    detection_index: int = -1


_STATUS = (TrackStatus.TENTATIVE, TrackStatus.CONFIRMED, TrackStatus.LOST)
_STATUS_CODE = {s: i for i, s in enumerate(_STATUS)}


def _column(name: str, values: np.ndarray, dtype: type, k: int) -> np.ndarray:
    """``values`` as ``(k,)`` of ``dtype``; ``ValueError`` naming ``Tracks.<name>`` for another number of values."""
    column: np.ndarray = np.asarray(values, dtype=dtype)
    if column.size != k:
        raise ValueError(f"Tracks.{name}: has {column.size} values but the batch has {k}")
    return column.reshape(k)


def _status_codes(status: np.ndarray | Sequence[TrackStatus]) -> np.ndarray:
    """Status codes from codes, or from :class:`TrackStatus` values (as ``Lifecycle.status`` gives them)."""
    values = np.asarray(status)
    if values.dtype != object:
        return values
    codes = []
    for value in values.reshape(-1).tolist():
        if not isinstance(value, TrackStatus):
            raise ValueError(f"Tracks.status: give TrackStatus values or codes 0 (tentative), 1 (confirmed), "
                             f"2 (lost), got {value!r}")
        codes.append(_STATUS_CODE[value])
    return np.array(codes, dtype=np.int8)


class Tracks(Sequence[TrackSnapshot]):
    """The tracks a tracker reports for one frame, as columns; iterating or indexing gives :class:`TrackSnapshot`s.

    Attributes:
        id: ``(k,)`` track ids.
        status: ``(k,)`` status codes (0 tentative, 1 confirmed, 2 lost; :meth:`statuses` as enums); the
            constructor also takes one :class:`TrackStatus` for all, or one per track.
        xywh: ``(k, 4)`` boxes in pixels, or None for world-only trackers.
        position: ``(k, 2)`` ground positions in metres, or None.
        velocity: ``(k, d)`` velocities (pixels/s or metres/s), or None.
        heading: ``(k,)`` headings in radians (NaN: none), or None.
        agent_id: ``(k,)`` identified agents (-1: none), or None.
        identity_prob: ``(k,)`` confidences of ``agent_id`` (NaN: none), or None.
        detection_index: ``(k,)`` index of the detection that updated each track this frame, or -1."""

    __slots__ = ("id", "status", "xywh", "position", "velocity", "heading", "agent_id", "identity_prob",
                 "detection_index")

    def __init__(self, id: np.ndarray, status: np.ndarray | TrackStatus | Sequence[TrackStatus], *,
                 xywh: np.ndarray | None = None, position: np.ndarray | None = None, velocity: np.ndarray | None = None,
                 heading: np.ndarray | None = None, agent_id: np.ndarray | None = None,
                 identity_prob: np.ndarray | None = None, detection_index: np.ndarray | None = None) -> None:
        fraction = first_fraction(id)
        if fraction is not None:
            raise ValueError(f"Tracks.id: row {fraction} is not a whole number ({np.ravel(id)[fraction]!r})")
        self.id = np.asarray(id, dtype=int).reshape(-1)
        k = len(self.id)
        if isinstance(status, TrackStatus):
            self.status = np.full(k, _STATUS_CODE[status], dtype=np.int8)
        else:
            self.status = _column("status", _status_codes(status), np.int8, k)
            if ((self.status < 0) | (self.status >= len(_STATUS))).any():
                raise ValueError(f"Tracks.status: codes are 0 (tentative), 1 (confirmed) or 2 (lost), got "
                                 f"{sorted(set(self.status.tolist()))}")
        self.xywh, self.position, self.velocity, self.heading = xywh, position, velocity, heading
        self.agent_id, self.identity_prob = agent_id, identity_prob
        self.detection_index = (np.full(k, -1, dtype=int) if detection_index is None
                                else _column("detection_index", detection_index, int, k))
        for name in ("xywh", "position", "velocity", "heading", "agent_id", "identity_prob"):
            col = getattr(self, name)
            if col is not None and len(col) != k:
                raise ValueError(f"Tracks.{name}: has {len(col)} rows but the batch has {k}")
        for name, width in (("xywh", 4), ("position", 2)):
            col = getattr(self, name)
            if col is not None and np.shape(col)[1:] != (width,):
                raise ValueError(f"Tracks.{name}: rows of {width} numbers expected, got shape {np.shape(col)}")

    @classmethod
    def trusted(cls, id: np.ndarray, status: np.ndarray, xywh: np.ndarray, velocity: np.ndarray,
                detection_index: np.ndarray) -> Tracks:
        """Box tracks from columns a tracker built itself, without the checks of ``__init__``."""
        out = cls.__new__(cls)
        out.id, out.status, out.xywh, out.velocity, out.detection_index = id, status, xywh, velocity, detection_index
        out.position = out.heading = out.agent_id = out.identity_prob = None
        return out

    @classmethod
    def empty(cls) -> Tracks:
        """No tracks."""
        return cls(np.zeros(0, dtype=int), TrackStatus.CONFIRMED)

    @classmethod
    def from_snapshots(cls, snapshots: Sequence[TrackSnapshot]) -> Tracks:
        """Columns from snapshots (a column is None when every snapshot lacks it)."""
        snaps = list(snapshots)

        def column(name: str, missing: float) -> np.ndarray | None:
            values = [getattr(s, name) for s in snaps]
            if not snaps or all(v is None for v in values):
                return None
            return np.array([missing if v is None else v for v in values], dtype=float)

        def rows(name: str) -> np.ndarray | None:
            values = [getattr(s, name) for s in snaps]
            if not snaps or any(v is None for v in values):
                return None
            return np.array(values, dtype=float)

        agents = column("agent_id", -1)
        return cls(np.array([s.track_id for s in snaps], dtype=int),
                   np.array([_STATUS_CODE[s.status] for s in snaps], dtype=np.int8),
                   xywh=rows("xywh"), position=rows("position"), velocity=rows("velocity"),
                   heading=column("heading", np.nan), agent_id=None if agents is None else agents.astype(int),
                   identity_prob=column("identity_prob", np.nan),
                   detection_index=np.array([s.detection_index for s in snaps], dtype=int))

    def __len__(self) -> int:
        return len(self.id)

    @overload
    def __getitem__(self, i: int) -> TrackSnapshot: ...

    @overload
    def __getitem__(self, i: slice) -> list[TrackSnapshot]: ...

    def __getitem__(self, i: int | slice) -> TrackSnapshot | list[TrackSnapshot]:
        if isinstance(i, slice):
            return [self[j] for j in range(*i.indices(len(self)))]
        if not -len(self) <= i < len(self):
            raise IndexError(f"track {i} of {len(self)}")
        heading = None if self.heading is None or np.isnan(self.heading[i]) else float(self.heading[i])
        agent = None if self.agent_id is None or self.agent_id[i] < 0 else int(self.agent_id[i])
        prob = (None if self.identity_prob is None or np.isnan(self.identity_prob[i])
                else float(self.identity_prob[i]))
        return TrackSnapshot(
            track_id=int(self.id[i]), status=_STATUS[self.status[i]],
            xywh=None if self.xywh is None else self.xywh[i],
            position=None if self.position is None else self.position[i],
            velocity=None if self.velocity is None else self.velocity[i],
            heading=heading, agent_id=agent, identity_prob=prob, detection_index=int(self.detection_index[i]))

    def __iter__(self) -> Iterator[TrackSnapshot]:
        return (self[i] for i in range(len(self)))

    def __eq__(self, other: object) -> bool:
        """Equal to a list of snapshots only when both are empty (snapshots compare by identity)."""
        if isinstance(other, (list, tuple)):
            return len(self) == 0 and len(other) == 0
        return NotImplemented

    __hash__ = None  # type: ignore[assignment]

    def __repr__(self) -> str:
        return f"Tracks({len(self)} tracks, ids {self.id.tolist()})"

    def statuses(self) -> list[TrackStatus]:
        """The status of every track as an enum."""
        return [_STATUS[c] for c in self.status]

    def to_rows(self, frame_index: int) -> np.ndarray:
        """MOTChallenge result rows ``(k, 10)`` for the 0-based ``frame_index`` (none without boxes):
        frame (1-based), id, box, confidence (``identity_prob``, 1 when none), -1, -1, -1."""
        if self.xywh is None:
            return np.full((0, 10), -1.0)
        rows = np.full((len(self), 10), -1.0)
        rows[:, 0] = frame_index + 1
        rows[:, 1] = self.id
        rows[:, 2:6] = self.xywh
        rows[:, 6] = 1.0 if self.identity_prob is None else np.where(np.isnan(self.identity_prob), 1.0,
                                                                      self.identity_prob)
        return rows
