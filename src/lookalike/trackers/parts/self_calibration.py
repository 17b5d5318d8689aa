"""Statistics a tracker gathers on its own tracks to calibrate itself to a detector, without ground truth.

:class:`ScoreBands`: the score band where confident detections start; :class:`MissReturns`: how long a missed track is
likely still present. Both only count; the tracker decides."""

from __future__ import annotations

import math

import numpy as np

_Z = 1.645  # one-sided 95% normal quantile of the Wilson lower bound
_FEW = 10  # ScoreCalibration counts up to this many scores a frame as Python numbers (faster below ~12)


def _bin_of(score: np.ndarray, bins: int) -> np.ndarray:
    """``(n,)`` bin of each score among ``bins`` equal bins on [0, 1] (scores outside go to the end bins)."""
    b: np.ndarray = (score * bins).astype(int)
    np.minimum(b, bins - 1, out=b)
    np.maximum(b, 0, out=b)
    return b


def _clipped(bins: list[int], top: int) -> list[int]:
    """``bins`` clipped to [0, ``top``] (the list itself when all are inside)."""
    if bins and (min(bins) < 0 or max(bins) > top):
        return [min(max(b, 0), top) for b in bins]
    return bins


class ScoreBands:
    """Per score band (``bands`` equal bands on [0, 1]): detections seen and those that continued a confirmed track."""

    def __init__(self, bands: int = 10) -> None:
        self.bands = bands
        self.seen = np.zeros(bands, dtype=np.int64)
        self.kept = np.zeros(bands, dtype=np.int64)

    def add(self, score: np.ndarray, continued: np.ndarray) -> None:
        """Count detections with ``score`` (in [0, 1]); ``continued`` indexes those that continued a track."""
        self.add_bands(_bin_of(np.asarray(score), self.bands), continued)

    def add_bands(self, band: np.ndarray, continued: np.ndarray) -> None:
        """:meth:`add` given each detection's band ``(n,)`` (``_bin_of(score, bands)``)."""
        self.seen += np.bincount(band, minlength=self.bands)
        self.kept += np.bincount(band[continued], minlength=self.bands)

    def threshold(self, ratio: float, min_count: int) -> float:
        """The lowest score the evidence supports as confident (1.0 before any band has ``min_count``).

        Going down from the highest judged band (``min_count`` detections), each band whose share of continued
        detections (one-sided 95% Wilson lower bound) is at least ``ratio`` times the best judged share lowers the
        threshold to its lower edge; the first band that fails or is not judged stops the descent."""
        # Only the bands the descent visits are computed, one at a time (the same float operations as the
        # whole-array form, so the same threshold to the last bit).
        seen, kept = self.seen.tolist(), self.kept.tolist()
        judged = [n >= min_count for n in seen]
        if not any(judged):
            return 1.0
        rate = [k / max(n, 1) if j else 0.0 for n, k, j in zip(seen, kept, judged)]
        best = ratio * max(rate)
        z2 = _Z**2
        b = len(judged) - 1 - judged[::-1].index(True)
        while b > 0 and judged[b - 1]:
            n, r = max(seen[b - 1], 1), rate[b - 1]
            low = (r + z2 / (2 * n) - _Z * math.sqrt(r * (1 - r) / n + z2 / (4 * n * n))) / (1 + z2 / n)
            if not low >= best:
                break
            b -= 1
        return b / self.bands


class MissReturns:
    """Per miss length j (frames, 1..``longest``): confirmed tracks missed at least j frames that came
    back, and those that died."""

    def __init__(self, longest: int = 10) -> None:
        self.longest = longest
        self.returned = np.zeros(longest + 1, dtype=np.int64)
        self.ended = np.zeros(longest + 1, dtype=np.int64)
        self._version = 0  # counts added so far (calls that changed them): keys likely_present's cached table
        self._ok: tuple[tuple[int, float, int], np.ndarray] | None = None

    def _add(self, counts: np.ndarray, missed: np.ndarray) -> None:
        m = np.minimum(missed[missed > 0], self.longest)
        if len(m):
            counts[1:] += np.cumsum(np.bincount(m, minlength=self.longest + 1)[::-1])[::-1][1:]
            self._version += 1

    def came_back(self, missed: np.ndarray) -> None:
        """Tracks updated again after ``missed`` frames without a detection."""
        self._add(self.returned, np.asarray(missed))

    def died(self, missed: np.ndarray) -> None:
        """Tracks dropped after ``missed`` frames without a detection."""
        self._add(self.ended, np.asarray(missed))

    def likely_present(self, missed: np.ndarray, share: float, min_count: int) -> np.ndarray:
        """Per track missed ``missed`` frames: whether, for every miss length up to its own, at least
        ``share`` of at least ``min_count`` resolved tracks (came back or died) came back."""
        # negative lengths seen as unsigned are beyond ``longest`` too
        length = np.asarray(missed, dtype=np.int64).view(np.uint64)
        out: np.ndarray = self.present_table(share, min_count)[np.minimum(length, self.longest + 1)]
        return out

    def present_table(self, share: float, min_count: int) -> np.ndarray:
        """:meth:`likely_present` as a table ``(longest + 2,)`` over miss lengths 0 … ``longest + 1`` (the last
        entry, False, stands for every longer or negative length; 0 is False). Cached until the counts change."""
        key = (self._version, share, min_count)
        if self._ok is None or self._ok[0] != key:
            resolved = self.returned + self.ended
            ok = (resolved >= min_count) & (self.returned >= share * resolved)
            ok[0] = True
            ok = np.logical_and.accumulate(ok)
            ok[0] = False
            self._ok = (key, np.append(ok, False))  # one more False: every length beyond ``longest``
        return self._ok[1]


class ScoreCalibration:
    """Owner of a tracker's score thresholds: observes scores and which detections continued confirmed tracks, and
    decides each frame's high, birth and tentative thresholds.

    ``high_score`` and ``birth_score`` are ceilings, lowered to a quantile of the scores seen (``bins`` bins on [0, 1])
    when their quantile is set, the high one also to the :class:`ScoreBands` threshold with ``high_match_ratio``. Always
    tentative <= high <= birth."""

    def __init__(self, high_score: float, birth_score: float, *, high_quantile: float | None = None,
                 birth_quantile: float | None = None, tentative_quantile: float | None = None,
                 high_match_ratio: float | None = None, calib_min_count: int = 100, bins: int = 1000,
                 clutter_factor: float | None = None, clutter_floor: float = 0.1) -> None:
        self.high_score, self.birth_score = high_score, birth_score
        self.high_quantile, self.birth_quantile = high_quantile, birth_quantile
        self.tentative_quantile = tentative_quantile
        self.high_match_ratio, self.calib_min_count = high_match_ratio, calib_min_count
        self.bins = bins
        self.clutter_factor, self.clutter_floor = clutter_factor, clutter_floor
        self.histogram = np.zeros(bins, dtype=np.int64)  # scores seen so far, binned on [0, 1]
        self.bands = ScoreBands(10)  # 0.1-wide bands: detections, and those that continued tracks
        self._total = 0  # scores counted in the histogram
        # each quantile's last [bin, scores in bins up to it]: decide walks from there (no cumulative sum)
        self._at: dict[str, list[int]] = {}
        self._scales = np.array([float(bins), float(self.bands.bands)])  # histogram bins and bands at once
        self._top = np.array([bins - 1, self.bands.bands - 1])
        self._last: tuple[np.ndarray, np.ndarray | list[int]] | None = None  # (scores, their bands) of observe_scores

    @property
    def _quantiles(self) -> bool:
        return not (self.high_quantile is None and self.birth_quantile is None and self.tentative_quantile is None
                    and self.clutter_factor is None)

    def observe_scores(self, score: np.ndarray) -> None:
        """Count this frame's scores (in [0, 1]) into the running distribution."""
        if not self._quantiles:
            return
        if len(score) <= _FEW:  # a few scores: Python numbers (the same products and truncations)
            self._observe_few(score)
            return
        if self.high_match_ratio is not None:  # the bands observe_continued will want, in the same pass
            both = (score[:, None] * self._scales).astype(int)  # _bin_of for both bin counts
            np.minimum(both, self._top, out=both)
            np.maximum(both, 0, out=both)
            b, self._last = both[:, 0], (score, both[:, 1])
        else:
            b = _bin_of(score, self.bins)
        self.histogram += np.bincount(b, minlength=self.bins)
        self._total += len(b)
        if self._at:
            new = b.tolist()
            for at in self._at.values():
                i = at[0]
                at[1] += len([v for v in new if v <= i])

    def _observe_few(self, score: np.ndarray) -> None:
        """:meth:`observe_scores` for a few scores, one at a time: ``int`` truncates ``score · bins`` as
        ``astype(int)`` does (scores are finite), then the same clipping to the end bins."""
        values = score.tolist()
        top, scale = self.bins - 1, float(self.bins)
        hist_bins = _clipped([int(v * scale) for v in values], top)
        hist = self.histogram
        for b in hist_bins:
            hist[b] += 1
        self._total += len(hist_bins)
        if self.high_match_ratio is not None:
            top_band, band_scale = self.bands.bands - 1, float(self.bands.bands)
            self._last = (score, _clipped([int(v * band_scale) for v in values], top_band))
        for at in self._at.values():
            i = at[0]
            at[1] += len([v for v in hist_bins if v <= i])

    def observe_continued(self, score: np.ndarray, continued: np.ndarray) -> None:
        """Count this frame's detections by band; ``continued`` indexes those that continued a confirmed track."""
        if self.high_match_ratio is not None:
            last = self._last
            if last is not None and last[0] is score:
                band = last[1]
                if isinstance(band, list):  # observe_scores' few scores, counted one at a time
                    seen, kept = self.bands.seen, self.bands.kept
                    for b in band:
                        seen[b] += 1
                    for j in continued.tolist():
                        kept[band[j]] += 1
                else:
                    self.bands.add_bands(band, continued)
            else:
                self.bands.add(score, continued)

    def _edge(self, name: str, q: float) -> int:
        """The first histogram bin whose cumulative count reaches ``q`` times the total (``searchsorted``
        on the cumulative histogram, side left; ``bins`` if none), walked from where the quantile
        ``name`` was last found: it moves a few bins between frames."""
        target = q * self._total
        hist = self.histogram
        at = self._at.get(name)
        if at is None:
            at = self._at[name] = [0, hist.item(0)]
        i, c = at
        if c < target:
            last = len(hist) - 1
            while c < target and i < last:
                i += 1
                c += hist.item(i)
            at[0], at[1] = i, c
            return i if c >= target else len(hist)
        while i > 0 and c - hist.item(i) >= target:
            c -= hist.item(i)
            i -= 1
        at[0], at[1] = i, c
        return i

    def decide(self, clutter_share: float | None = None) -> tuple[float, float, float]:
        """This frame's ``(high, birth, tentative)`` score thresholds; ``clutter_share`` (the share of
        detections that are likely clutter, :class:`~lookalike.trackers.parts.clutter.ClutterShare`) with
        ``clutter_factor`` set lowers the birth one to the quantile ``clutter_factor·clutter_share``
        (at least ``clutter_floor``) of the scores seen; to the median while the share is None."""
        high, birth = self.high_score, self.birth_score
        if self.high_match_ratio is not None:
            high = min(high, self.bands.threshold(self.high_match_ratio, self.calib_min_count))
        if not self._quantiles:
            return min(high, birth), birth, min(high, birth)
        tentative = 1.0
        if self._total:
            # the lower edge of the bin holding each q-quantile: never above a score it stands for
            bins = self.bins
            if self.high_quantile is not None:
                high = min(high, self._edge("high", self.high_quantile) / bins)
            if self.birth_quantile is not None:
                birth = min(birth, self._edge("birth", self.birth_quantile) / bins)
            if self.clutter_factor is not None:  # before the share is judged: the median
                q = 0.5 if clutter_share is None else max(self.clutter_factor * clutter_share, self.clutter_floor)
                birth = min(birth, self._edge("clutter", min(q, 0.5)) / bins)  # never above the median
            if self.tentative_quantile is not None:
                tentative = self._edge("tentative", self.tentative_quantile) / bins
        high = min(high, birth)
        return high, birth, min(high, tentative)
