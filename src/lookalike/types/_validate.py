"""Shared column validation for the columnar batch types."""

from __future__ import annotations

from typing import Any

import numpy as np


def first_fraction(values: Any) -> int | None:
    """The flat index of the first of ``values`` that is not a finite whole number (a fraction, NaN or infinity);
    None when all are (integer arrays always)."""
    given = np.asarray(values)
    if given.dtype.kind not in "fc" or not given.size:
        return None
    bad = np.flatnonzero(~(np.isfinite(given) & (given == np.round(given))))
    return int(bad[0]) if len(bad) else None


def as_column(
    owner: str, name: str, value: Any, n: int | None, width: int | None, dtype: type = float
) -> np.ndarray:
    """``value`` as a read-only array ``(n,)`` or ``(n, width)``; ``ValueError`` naming ``owner.name`` otherwise (and
    for an ``int`` column given numbers that are not whole)."""
    if dtype is int and isinstance(value, (np.ndarray, list, tuple)):
        k = first_fraction(value)
        if k is not None:
            raise ValueError(f"{owner}.{name}: {np.asarray(value).ravel()[k]} is not a whole number")
    try:
        arr: np.ndarray = np.array(value, dtype=dtype, copy=True)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"{owner}.{name}: cannot convert to {dtype.__name__} array ({exc})") from None
    if width is None:
        if arr.ndim == 0 or arr.ndim > 1:
            if arr.size == 0:
                arr = arr.reshape(0)
            else:
                raise ValueError(f"{owner}.{name}: expected shape (n,), got {arr.shape}")
    else:
        if arr.size == 0:
            arr = arr.reshape(0, width)
        if arr.ndim != 2 or arr.shape[1] != width:
            raise ValueError(f"{owner}.{name}: expected shape (n, {width}), got {arr.shape}")
    if n is not None and arr.shape[0] != n:
        raise ValueError(f"{owner}.{name}: has {arr.shape[0]} rows but the batch has {n}")
    arr.setflags(write=False)
    return arr


def require_finite(owner: str, name: str, arr: np.ndarray) -> None:
    """Raise ``ValueError`` naming the first row of ``arr`` that holds NaN or infinity."""
    bad = ~np.isfinite(arr)
    if bad.any():
        row = int(np.argwhere(bad)[0][0])
        raise ValueError(f"{owner}.{name}: row {row} is not finite ({arr[row]!r})")


def reject_unknown(owner: str, given: dict[str, Any], known: tuple[str, ...]) -> None:
    """Raise ``ValueError`` for keys of ``given`` that are not fields of ``owner``."""
    unknown = sorted(set(given) - set(known))
    if unknown:
        raise ValueError(f"{owner}: unknown field(s) {unknown}; known fields are {list(known)}")
