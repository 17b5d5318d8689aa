"""``TrackTable``: a tracker's tracks as named numpy columns, one row per track.

Standard columns: ``ids`` (1-based, per table), ``mean (k, n)`` and ``cov`` of the motion state, ``hits``, ``misses``
(frames), ``unseen_s`` (seconds) and ``confirmed``; a tracker declares extra columns."""

from __future__ import annotations

from typing import Any

import numpy as np

ColumnSpec = tuple[tuple[int, ...], Any]

_CORE: dict[str, ColumnSpec] = {
    "ids": ((), int),
    "hits": ((), int),
    "misses": ((), int),
    "unseen_s": ((), float),
    "confirmed": ((), bool),
}


class TrackTable:
    """Tracks as equal-length columns; rows are added by :meth:`add` and removed by :meth:`keep`."""

    ids: np.ndarray
    mean: np.ndarray
    cov: np.ndarray
    hits: np.ndarray
    misses: np.ndarray
    unseen_s: np.ndarray
    confirmed: np.ndarray

    def __init__(self, state_dim: int, extra: dict[str, ColumnSpec] | None = None,
                 cov_shape: tuple[int, ...] | None = None) -> None:
        """A table for states of ``state_dim`` numbers plus ``extra`` columns (name → (trailing shape, dtype); a name
        of a standard column or of a method, such as ``age``, raises ``ValueError``);
        ``cov_shape``: the covariance's trailing shape when the motion space keeps it compact (default
        ``(state_dim, state_dim)``)."""
        taken = sorted(name for name in extra or {} if name in _CORE or name in ("mean", "cov", "next_id")
                       or name.startswith("_") or hasattr(TrackTable, name))
        if taken:
            raise ValueError(f"TrackTable: column name(s) {taken} are taken by the table's own columns or methods")
        cov = (state_dim, state_dim) if cov_shape is None else tuple(cov_shape)
        self._spec: dict[str, ColumnSpec] = {
            **_CORE, "mean": ((state_dim,), float), "cov": (cov, float), **(extra or {})}
        self.clear()

    def clear(self) -> None:
        """Remove every row; ids restart at 1."""
        for name, (shape, dtype) in self._spec.items():
            setattr(self, name, np.zeros((0,) + shape, dtype=dtype))
        self.next_id = 1

    @property
    def columns(self) -> tuple[str, ...]:
        """The column names."""
        return tuple(self._spec)

    def __len__(self) -> int:
        return len(self.ids)

    def __getitem__(self, name: str) -> np.ndarray:
        if name not in self._spec:
            raise KeyError(f"TrackTable has no column {name!r}; columns: {', '.join(self._spec)}")
        return getattr(self, name)  # type: ignore[no-any-return]

    def __setitem__(self, name: str, value: np.ndarray) -> None:
        if name not in self._spec:
            raise KeyError(f"TrackTable has no column {name!r}; columns: {', '.join(self._spec)}")
        setattr(self, name, value)

    def add(self, mean: np.ndarray, cov: np.ndarray, **values: Any) -> np.ndarray:
        """Append tracks with new ids; columns not given start at zero (scalars broadcast). A column of another
        shape than ``(len(mean),) + its row shape`` raises ``ValueError`` naming it, and leaves the table as it was.

        Returns the row indices of the new tracks."""
        n = len(mean)
        unknown = set(values) - set(self._spec)
        if unknown:
            raise KeyError(f"TrackTable has no column(s) {sorted(unknown)}")
        start = len(self.ids)
        given = {**values, "mean": mean, "cov": cov,
                 "ids": np.arange(self.next_id, self.next_id + n)}
        rows: dict[str, np.ndarray] = {}
        for name, (shape, dtype) in self._spec.items():
            new = given.get(name)
            if new is None:
                new = np.zeros((n,) + shape, dtype=dtype)
            elif np.ndim(new) == 0:
                new = np.full((n,) + shape, new, dtype=dtype)
            elif np.shape(new) != (n,) + shape:
                raise ValueError(f"TrackTable.add: column {name!r} has shape {np.shape(new)}, expected "
                                 f"{(n,) + shape} ({n} new tracks)")
            rows[name] = new
        self.next_id += n
        for name, new in rows.items():
            setattr(self, name, np.concatenate([getattr(self, name), new]))
        return np.arange(start, start + n)

    def keep(self, mask: np.ndarray) -> None:
        """Keep the rows where ``mask`` is True (or the rows indexed by it)."""
        for name in self._spec:
            setattr(self, name, getattr(self, name)[mask])

    def age(self) -> None:
        """One more frame without an update for every track (``misses`` + 1)."""
        self.misses += 1

    def record(self, hit: np.ndarray, dt: float) -> None:
        """After matching: tracks with ``hit`` (a boolean mask ``(k,)``; else ``ValueError``) were updated (``misses``,
        ``unseen_s`` reset), the others missed one more frame of ``dt`` seconds."""
        if not isinstance(hit, np.ndarray) or hit.dtype != np.bool_ or hit.shape != self.misses.shape:
            given = f"{getattr(hit, 'dtype', type(hit).__name__)} of shape {np.shape(hit)}"
            raise ValueError(f"TrackTable.record: hit must be a boolean mask of shape {self.misses.shape}, got "
                             f"{given} (a matching's det_of_track >= 0, not the indices themselves)")
        self.misses = np.where(hit, 0, self.misses + 1)
        self.unseen_s = np.where(hit, 0.0, self.unseen_s + dt)

    def copy_row(self, source: int, target: int, names: tuple[str, ...]) -> None:
        """Overwrite columns ``names`` of row ``target`` with row ``source``'s values."""
        for name in names:
            self[name][target] = self[name][source]
