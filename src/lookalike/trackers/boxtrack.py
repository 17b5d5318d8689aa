"""BoxTrack: a motion-only box tracker for look-alike targets (lookalike's own, no appearance).

Built on SORT's idea (Kalman filter + Hungarian matching on IoU) with what makes identities last:

- **State** ``[cx, cy, w, h, vx, vy, vw, vh]`` in pixels and pixels/frame, with process and
  measurement noise proportional to the box size (``pos_noise``·w/h, ``vel_noise``·w/h), so one
  filter suits near and far targets alike.
- **Two-stage association with a score split** (as ByteTrack): detections scoring at least
  ``high_score`` are matched first to the confirmed tracks on ``1 - IoU·score`` (pairs need IoU ≥
  ``match_iou``), those missed at most ``recent_frames`` frames before longer-lost ones (whose boxes are
  stale guesses that could otherwise take a live neighbour's detection); then detections between ``low_score`` and
  ``high_score`` may only continue tracks updated in the previous frame (IoU ≥ ``low_iou``); then
  tentative tracks take the remaining confident detections (IoU ≥ ``tentative_iou``).
- **Re-identification by motion**: a lost track keeps coasting for ``max_age_s`` seconds. Left-over
  confident detections are matched to lost tracks on the distance between box centres divided by the
  track's height, gated at ``reid_distance`` (plus ``reid_growth`` per second lost), with widths and
  heights within a factor ``reid_scale``. A lost track stops extrapolating its velocity after
  ``coast_s`` seconds, so it waits near where it was last seen instead of drifting away.
- **Birth/death**: a left-over detection scoring at least the birth threshold starts a tentative
  track, confirmed after ``n_init`` consecutive hits (immediately in the first frame); a tentative
  track dies at its first miss, a confirmed one after ``max_age_s`` seconds without an update.
  Detector scores are not calibrated alike across detectors, so the thresholds follow the
  sequence's own running score distribution (a histogram of 1000 bins on [0, 1] of every score
  ≥ ``low_score`` seen so far, this frame's included): the birth threshold is ``min(birth_score,
  birth_quantile)`` and the high one ``min(high_score, high_quantile)``; the absolute values
  (calibrated on MOT15's Faster R-CNN) are ceilings, so a detector scoring lower than MOT15's gets
  lower thresholds while MOT15's own scores mostly keep theirs. The high threshold never exceeds the
  birth threshold: a detection good enough to start a track is good enough to continue one.
  ``tentative_quantile`` (off by default) lets tentative tracks also take detections below the high
  threshold that score at least that quantile (with IoU ≥ ``tentative_iou``).
- **Self-calibration on the sequence's own tracks** (issue #10; no ground truth involved): a detector's
  scores say little until one knows how that detector scores. Per 0.1-wide score band, boxtrack counts
  the detections and those that continued a confirmed track by overlap (the first two stages); going
  down from the highest band, the high threshold is lowered to every band whose share (its one-sided
  95% Wilson lower bound, after ``calib_min_count`` detections) is at least ``high_match_ratio`` times
  the best band's (:mod:`lookalike.trackers.self_calibration`). On MOT15's Faster R-CNN, detections below 0.9 continue tracks less than half as often
  as those above (mostly clutter), so nothing changes; on a detector scoring its true boxes evenly from
  0.6 to 1 the threshold falls to 0.6. Likewise, per miss length j (frames), it counts confirmed tracks
  that came back after at least j misses and those that died; while at least ``coast_report_prob`` of
  those (after ``coast_min_count``) came back, a track missed j frames is reported at its predicted
  box (``detection_index`` −1). Detectors that drop people at random get the gaps bridged online;
  MOT15's misses (occlusions and exits: about half come back) are not.
- **Closed-set identity** (``max_targets``): when the number of targets is known (23 pigs), at most
  ``max_targets`` tracks exist at once, confirmed tracks never die, and left-over detections are
  assigned to lost tracks by centre distance alone (gated at ``closed_distance`` box heights), so an
  identity is recovered rather than replaced.

A track is reported in a frame when it is confirmed and matched a detection in that frame (or is
coasted, above); its box is the filtered one (``report="filtered"``) or the detection's (``"detection"``).

Parameter choice (no tuning on the scored data): every default was chosen on the *first half* of
each of the 7 MOT15 training sequences (frames 1..⌊N/2⌋, detections and ground truth cut there,
scores combined), maximising HOTA + IDF1 + MOTA, with ``benchmarks/real_boxtrack_grid.py``:
``high_score`` ∈ {0.7, 0.8, 0.9}, ``birth_score`` ∈ {0.8, 0.9, 0.95}, ``low_score`` ∈ {0.5, 0.7},
``match_iou`` ∈ {0.2, 0.3}, ``report`` (first grid); then ``max_age_s`` ∈ {0.5, 1, 2}, ``n_init`` ∈
{2, 3}, ``reid_growth`` ∈ {0, 1}, ``coast_s`` ∈ {0.5, ∞}; then ``pos_noise`` ∈ {1/20, 1/10},
``vel_noise`` ∈ {1/160, 1/80}, ``low_iou`` ∈ {0.3, 0.5}, ``tentative_iou`` ∈ {0.2, 0.3}; then
``high_quantile`` ∈ {off, 0.2, 0.3}, ``birth_quantile`` ∈ {off, 0.3, 0.5}. First halves: HOTA 43.6,
IDF1 58.9, MOTA 51.2; whole sequences (the second halves unseen): HOTA 41.2, IDF1 55.1, MOTA 52.2.
Issue #10 (adaptive scores; chosen on MOT15 and pigs first halves only, before mot17-synth was scored
again): ``high_quantile`` ∈ {off, 0.25, 0.3, 0.35, 0.4, 0.5} × ``tentative_quantile`` ∈ {off, 0, 0.1,
…, 0.5}; MOT15 (defaults) HOTA + IDF1 + MOTA 153.77 → 153.91 with ``high_quantile`` 0.35 (all within
±0.3: MOT15's scores sit above the ceilings), pigs unchanged; ``tentative_quantile`` 0 (tentative
tracks take any detection ≥ ``low_score``) 153.74 and pigs 0.16 lower, 0.1–0.3 no better, so it stays
off. Also tried: quantiles only after 30–300 scores (±0.1). MOT15's per-sequence parameters of
``lookalike bench real`` were chosen without these and keep them off (with them: 161.41 → 160.06).
Then scored once on mot17-synth (a detector scoring 0.6–1): ``boxtrack`` HOTA/IDF1/MOTA 45.05/55.57/
55.59 → 48.49/58.95/60.39 (still 7th of 10), ``boxtrack-offline`` 56.69/65.04/71.36 (3rd);
``mot17-synth2`` (other noise seeds) was not looked at.
Tried there and rejected (lower on the first halves): shifting lost tracks by the median offset of
matched ones (camera motion), restarting a returning track's velocity from its last two
observations, and recovering lost tracks by the IoU of their last detected box (OC-SORT's OCR).
Also rejected (issue #10; HOTA + IDF1 + MOTA on the first halves, 153.8 with the defaults): shifting
*every* track by the frame's median residual of tracked tracks matched within 0.5–2 heights (a global
camera shift; 136–148, and 150–154.0 when applied only beyond 2–5 standard errors, too little to keep),
letting low-score detections continue tracks lost up to 0.1–1 s (150–153.5), reporting lost tracks at
their predicted box for 0.1–0.4 s (146–153), and reid_scale 1.2/1.3/2 (152–153.4).
Self-calibration (issue #10), chosen on the first halves of MOT15, the pigs and ``mot17-synth`` (HOTA +
IDF1 + MOTA summed over the three; ``mot17-synth2`` and all second halves unseen): ``high_match_ratio``
∈ {off, 0.4, …, 0.8} × ``calib_min_count`` ∈ {10, 30, 100, 200, 400}: MOT15 unchanged (153.91) from 0.6
up, mot17-synth 178.0 → 194.9 (0.5–0.6 tie), pigs (closed set) 252.6 → 252.9 with 100 (250.6 with 30:
early bands judged on too few pigs); ``coast_report_prob`` ∈ {off, 0.6, …, 0.9} × ``coast_min_count`` ∈
{10, 30, 50}: MOT15 unchanged with 30 (10: 153.2–153.8), mot17-synth 194.9 → 212.2 (0.6–0.8 within 0.6),
pigs unchanged. Lower ``birth_quantile`` (0.2, 0.35) or ``n_init`` 2 gained about 1–3 on mot17-synth and
lost 0.5–4 on MOT15, so they stay.
Also tried then and rejected (first halves; ``mot17-synth`` / MOT15 HOTA + IDF1 + MOTA against 212.2 /
153.9): ``max_age_s`` 2–3 (up to 213.9 / down to 151.4), ``reid_distance`` 0–0.25 (212.3–212.9 / 150.3–150.5),
matching tracks seen in the previous frame before lost ones (a cascade: 202.7 / 154.5), an unweighted
first-stage cost (211.9 / 153.9), a measurement noise apart from ``pos_noise`` (0.025–0.2: 203.4–211.1
/ 132.4–151.8), and separate come-back shares for misses that start under other tracked boxes (on MOT15
over the whole sequences 71% of those come back against 42% of the others, but per first half there
are too few to judge: 210.8–211.2 / 153.9 unchanged, and 153.5–154.0 with ``coast_min_count`` 5–20).
Matching priority (issue #10, same sets and criterion): ``recent_frames`` ∈ {off, 1, 2, 3, 5, 10}: MOT15
153.9 → 152.9 / 155.1 / 155.1 / 154.9 / 154.6, mot17-synth 212.2 → 212.0 / 213.8 / 212.5 / 213.0 / 212.7,
pigs unchanged; 2 it is (0, a strict cascade, was rejected above). The per-sequence MOT15 parameters
were chosen before it (and use it).
Other detectors get their own thresholds, chosen on their own first halves (``lookalike bench real``,
which on MOT15 also uses parameters chosen per sequence on its first half; ``SEQUENCE_PARAMS``).
``max_targets`` is not tuned: it is the documented number of animals.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from lookalike.association.solver import assign
from lookalike.geometry.boxes import iou_matrix, xywh_to_cxcywh
from lookalike.motion import kalman
from lookalike.trackers.base import check_positive, param
from lookalike.trackers.registry import register_tracker
from lookalike.trackers.self_calibration import MissReturns, ScoreBands
from lookalike.trackers.timing import FrameClock
from lookalike.types import Frame, TrackSnapshot, TrackStatus

_H = np.hstack([np.eye(4), np.zeros((4, 4))])
_REPORTS = ("detection", "filtered")
_SCORE_BINS = 1000  # resolution of the score histogram behind the quantile thresholds (scores in [0, 1])
_MAX_COAST_FRAMES = 10  # longest miss (frames) after which a track may still be reported at its prediction


def _transition(steps: float) -> np.ndarray:
    F = np.eye(8)
    F[:4, 4:] = np.eye(4) * steps
    return F


def _to_xywh(cxcywh: np.ndarray) -> np.ndarray:
    out = np.array(cxcywh, dtype=float).reshape(-1, 4)
    out[:, 2:] = np.maximum(out[:, 2:], 1e-3)
    out[:, :2] -= out[:, 2:] / 2
    return out


@register_tracker("boxtrack")
class BoxTrack:
    """Motion-only box tracker: score-split association, motion re-identification, closed sets."""

    @dataclass(frozen=True)
    class Config:
        high_score: float = param(0.9, "detections scoring at least this are matched first and may start tracks")
        low_score: float = param(0.1, "detections below this are ignored")
        birth_score: float = param(0.95, "minimum score of a detection that starts a track")
        match_iou: float = param(0.3, "minimum IoU of a confident detection with a confirmed track")
        low_iou: float = param(0.5, "minimum IoU of a low-score detection with a tracked track")
        tentative_iou: float = param(0.3, "minimum IoU of a detection with a tentative track")
        n_init: int = param(3, "consecutive hits that confirm a track")
        max_age_s: float = param(1.0, "seconds a confirmed track survives without a detection")
        coast_s: float = param(0.5, "seconds a lost track keeps extrapolating its velocity")
        reid_distance: float = param(0.5, "centre distance (track heights) that re-identifies a lost track")
        reid_growth: float = param(0.0, "added to reid_distance per second lost (track heights)")
        reid_scale: float = param(1.5, "largest width/height ratio between a lost track and its detection")
        max_targets: int | None = param(None, "known number of targets (closed set), None when open")
        closed_distance: float = param(4.0, "closed set: centre distance (track heights) gating recovery")
        recent_frames: int | None = param(
            2, "confirmed tracks missed at most this many frames take confident detections before longer-lost "
               "ones (None: all at once)")
        pos_noise: float = param(1 / 20, "position noise per frame, as a fraction of the box size")
        vel_noise: float = param(1 / 160, "velocity noise per frame, as a fraction of the box size")
        high_quantile: float | None = param(
            0.35, "if set, high_score is lowered to this quantile of the scores seen so far")
        birth_quantile: float | None = param(
            0.5, "if set, birth_score is lowered to this quantile of the scores seen so far")
        tentative_quantile: float | None = param(
            None, "if set, tentative tracks also take detections scoring at least this quantile of the scores seen")
        high_match_ratio: float | None = param(
            0.6, "if set, high_score is lowered to the lowest 0.1-wide score bin from which every bin up continues "
                 "confirmed tracks at least this fraction as often as the best bin")
        coast_report_prob: float | None = param(
            0.7, "if set, a confirmed track missed for j frames is reported at its predicted box while this "
                 "sequence's tracks missed j frames came back at least this often")
        calib_min_count: int = param(100, "detections a score bin needs before high_match_ratio judges it")
        coast_min_count: int = param(30, "tracks missed j frames (come back or died) before coast_report_prob judges j")
        report: str = param("filtered", "reported box: 'detection' or 'filtered'")
        frame_interval_s: float | None = param(None, "seconds per frame (None: the smallest step seen)")

        def __post_init__(self) -> None:
            check_positive(self, "high_score", "low_score", "birth_score", "match_iou", "low_iou",
                           "tentative_iou", "coast_s", "reid_distance", "reid_growth", "recent_frames",
                           allow_zero=True)
            check_positive(self, "n_init", "max_age_s", "reid_scale", "max_targets", "closed_distance",
                           "pos_noise", "vel_noise", "frame_interval_s", "calib_min_count",
                           "coast_min_count")
            for name in ("high_quantile", "birth_quantile", "tentative_quantile", "high_match_ratio",
                         "coast_report_prob"):
                q = getattr(self, name)
                if q is not None and not 0 <= q <= 1:
                    raise ValueError(f"BoxTrack.Config.{name} must be in [0, 1], got {q}")
            if self.low_score > self.high_score:
                raise ValueError(f"BoxTrack.Config.low_score ({self.low_score}) exceeds high_score ({self.high_score})")
            if self.reid_scale < 1:
                raise ValueError(f"BoxTrack.Config.reid_scale must be >= 1, got {self.reid_scale}")
            if self.report not in _REPORTS:
                raise ValueError(f"BoxTrack.Config.report must be one of {_REPORTS}, got {self.report!r}")

    def __init__(self, config: BoxTrack.Config | None = None) -> None:
        self.config = config or BoxTrack.Config()
        self.reset()

    def reset(self) -> None:
        """Forget every track; ids restart at 1."""
        self._mean = np.zeros((0, 8))
        self._cov = np.zeros((0, 8, 8))
        self._ids = np.zeros(0, dtype=int)
        self._hits = np.zeros(0, dtype=int)
        self._missed = np.zeros(0, dtype=int)  # frames since the last update
        self._lost_s = np.zeros(0)  # seconds since the last update (0 when updated this frame)
        self._confirmed = np.zeros(0, dtype=bool)
        self._next_id = 1
        self._frame_count = 0
        self._clock = FrameClock(self.config.frame_interval_s)
        self._score_hist = np.zeros(_SCORE_BINS, dtype=np.int64)  # scores seen so far, binned on [0, 1]
        self._bands = ScoreBands(10)  # 0.1-wide score bands: detections, and those that continued tracks
        self._misses = MissReturns(_MAX_COAST_FRAMES)  # misses of confirmed tracks that came back / died

    # -- frame -----------------------------------------------------------------------------------

    def update(self, frame: Frame) -> list[TrackSnapshot]:
        """Advance all tracks to ``frame`` and match its detections."""
        cfg = self.config
        steps = self._clock.steps(frame.time)
        dt = steps * self._clock.interval
        self._frame_count += 1
        dets = frame.detections
        keep = dets.score >= cfg.low_score
        det_idx = np.flatnonzero(keep)
        det_box = xywh_to_cxcywh(dets.xywh[keep])
        score = dets.score[keep]
        high_score, birth_score, tentative_score = self._thresholds(score)
        was_tracked = self._lost_s == 0
        self._predict(steps, dt)
        det_of_track = np.full(len(self._ids), -1, dtype=int)
        free = np.ones(len(det_idx), dtype=bool)
        high = score >= high_score
        pred = _to_xywh(self._mean[:, :4])
        dxywh = dets.xywh[keep]

        def match(tracks: np.ndarray, cand: np.ndarray, min_iou: float, weigh: bool) -> None:
            if not len(tracks) or not len(cand):
                return
            iou = iou_matrix(pred[tracks], dxywh[cand])
            cost = 1.0 - (iou * score[cand][None, :] if weigh else iou)
            cost[iou < min_iou] = np.inf
            for r, c in assign(cost).matches:
                det_of_track[tracks[r]] = cand[c]
                free[cand[c]] = False

        recent = self._missed <= (np.inf if cfg.recent_frames is None else cfg.recent_frames)
        for group in (recent, ~recent):  # tracks seen lately first, then the longer-lost ones
            match(np.flatnonzero(self._confirmed & group), np.flatnonzero(free & high), cfg.match_iou, True)
        unmatched = lambda mask: np.flatnonzero(mask & (det_of_track < 0))
        match(unmatched(self._confirmed & was_tracked), np.flatnonzero(free & ~high), cfg.low_iou, False)
        if cfg.high_match_ratio is not None:  # only confirmed tracks matched so far, by overlap
            self._bands.add(score, det_of_track[det_of_track >= 0])
        match(unmatched(~self._confirmed), np.flatnonzero(free & high), cfg.tentative_iou, False)
        if tentative_score < high_score:  # ordinary scores for this detector, though below the high threshold
            match(unmatched(~self._confirmed), np.flatnonzero(free & ~high & (score >= tentative_score)),
                  cfg.tentative_iou, False)
        self._reidentify(unmatched(self._confirmed), np.flatnonzero(free & high), det_box, det_of_track, free)

        matched = np.flatnonzero(det_of_track >= 0)
        if len(matched):
            d = det_of_track[matched]
            R = self._noise(det_box[d, 2:], cfg.pos_noise)
            self._mean[matched], self._cov[matched] = kalman.update(
                self._mean[matched], self._cov[matched], det_box[d], _H, R)
            self._hits[matched] += 1
            self._lost_s[matched] = 0.0
            back = matched[self._confirmed[matched] & (self._missed[matched] > 0)]
            self._misses.came_back(self._missed[back])
        self._hits[det_of_track < 0] = 0
        self._missed = np.where(det_of_track >= 0, 0, self._missed + 1)
        self._confirmed |= (self._hits >= cfg.n_init) | ((self._frame_count == 1) & (self._hits > 0))
        born = self._births(np.flatnonzero(free & (score >= birth_score)), det_box)
        det_of_track = np.concatenate([det_of_track, born])
        out = self._report(det_of_track, det_idx, dets.xywh)
        self._prune()
        return out

    # -- steps -----------------------------------------------------------------------------------

    def _thresholds(self, score: np.ndarray) -> tuple[float, float, float]:
        """This frame's high, birth and tentative score thresholds (lowered to quantiles of the scores
        seen so far, this frame's included; the tentative one is the high one unless ``tentative_quantile``)."""
        cfg = self.config
        high, birth = cfg.high_score, cfg.birth_score
        if cfg.high_match_ratio is not None:
            high = min(high, self._bands.threshold(cfg.high_match_ratio, cfg.calib_min_count))
        if cfg.high_quantile is None and cfg.birth_quantile is None and cfg.tentative_quantile is None:
            return min(high, birth), birth, min(high, birth)
        tentative = 1.0
        bins = np.clip((score * _SCORE_BINS).astype(int), 0, _SCORE_BINS - 1)
        self._score_hist += np.bincount(bins, minlength=_SCORE_BINS)
        cum = np.cumsum(self._score_hist)
        if cum[-1]:
            # the lower edge of the bin holding the q-quantile: never above a score it stands for
            edge = lambda q: int(np.searchsorted(cum, q * cum[-1], side="left")) / _SCORE_BINS
            if cfg.high_quantile is not None:
                high = min(high, edge(cfg.high_quantile))
            if cfg.birth_quantile is not None:
                birth = min(birth, edge(cfg.birth_quantile))
            if cfg.tentative_quantile is not None:
                tentative = edge(cfg.tentative_quantile)
        high = min(high, birth)
        return high, birth, min(high, tentative)

    @staticmethod
    def _noise(size: np.ndarray, scale: float) -> np.ndarray:
        """``(k, 4, 4)`` diagonal covariances with std ``scale``·[w, h, w, h]."""
        std = scale * np.hstack([size, size])
        return np.einsum("ki,ij->kij", std**2, np.eye(4))

    def _predict(self, steps: float, dt: float) -> None:
        if not len(self._ids):
            return
        cfg = self.config
        size = np.maximum(self._mean[:, 2:4], 1.0)
        std = np.hstack([cfg.pos_noise * size, cfg.pos_noise * size, cfg.vel_noise * size, cfg.vel_noise * size])
        Q = np.einsum("ki,ij->kij", std**2 * max(steps, 0.0), np.eye(8))
        coasting = self._lost_s >= self.config.coast_s
        self._mean[coasting, 4:] = 0.0  # a long-lost track waits where it was last seen
        self._mean[:, 6:8] = np.where(self._mean[:, 2:4] + self._mean[:, 6:8] * steps <= 1.0, 0.0, self._mean[:, 6:8])
        self._mean, self._cov = kalman.predict(self._mean, self._cov, _transition(steps), Q)
        self._lost_s = self._lost_s + dt

    def _reidentify(self, tracks: np.ndarray, cand: np.ndarray, det_box: np.ndarray,
                    det_of_track: np.ndarray, free: np.ndarray) -> None:
        """Match lost confirmed tracks to left-over confident detections by centre distance."""
        if not len(tracks) or not len(cand):
            return
        cfg = self.config
        trk = self._mean[tracks, :4]
        det = det_box[cand]
        height = np.maximum(trk[:, 3:4], 1.0)
        dist = np.linalg.norm(trk[:, None, :2] - det[None, :, :2], axis=2) / height
        if cfg.max_targets is not None:
            gate = np.full((len(tracks), 1), cfg.closed_distance)
        else:
            gate = cfg.reid_distance + cfg.reid_growth * self._lost_s[tracks][:, None]
        ratio = np.abs(np.log(np.maximum(trk[:, None, 2:4], 1.0) / np.maximum(det[None, :, 2:4], 1.0))).max(axis=2)
        cost = np.where((dist <= gate) & (ratio <= np.log(cfg.reid_scale)), dist, np.inf)
        for r, c in assign(cost).matches:
            det_of_track[tracks[r]] = cand[c]
            free[cand[c]] = False

    def _births(self, new: np.ndarray, det_box: np.ndarray) -> np.ndarray:
        """Start tentative tracks on detections ``new``; returns the detections used."""
        cfg = self.config
        if cfg.max_targets is not None:
            new = new[: max(cfg.max_targets - len(self._ids), 0)]
        n = len(new)
        if not n:
            return new
        mean = np.hstack([det_box[new], np.zeros((n, 4))])
        size = np.maximum(det_box[new, 2:4], 1.0)
        std = np.hstack([2 * cfg.pos_noise * size, 2 * cfg.pos_noise * size, 10 * cfg.vel_noise * size,
                         10 * cfg.vel_noise * size])
        cov = np.einsum("ki,ij->kij", std**2, np.eye(8))
        self._mean = np.vstack([self._mean, mean])
        self._cov = np.concatenate([self._cov, cov])
        self._ids = np.concatenate([self._ids, np.arange(self._next_id, self._next_id + n)])
        self._next_id += n
        self._hits = np.concatenate([self._hits, np.ones(n, dtype=int)])
        self._missed = np.concatenate([self._missed, np.zeros(n, dtype=int)])
        self._lost_s = np.concatenate([self._lost_s, np.zeros(n)])
        self._confirmed = np.concatenate([self._confirmed, np.full(n, self._frame_count == 1 or cfg.n_init <= 1)])
        return new

    def _report(self, det_of_track: np.ndarray, det_idx: np.ndarray, det_xywh: np.ndarray) -> list[TrackSnapshot]:
        k = len(self._ids)
        det_of_track = det_of_track[:k]
        shown = np.flatnonzero(self._confirmed & (self._lost_s == 0) & (det_of_track >= 0))
        coasted = np.zeros(0, dtype=int)
        if self.config.coast_report_prob is not None:
            coasted = np.flatnonzero(self._confirmed & (det_of_track < 0) & self._misses.likely_present(
                self._missed[:k], self.config.coast_report_prob, self.config.coast_min_count))
        if not len(shown) and not len(coasted):
            return []
        original = det_idx[det_of_track[shown]]
        if self.config.report == "detection":
            boxes = det_xywh[original]
        else:
            boxes = _to_xywh(self._mean[shown, :4])
        if len(coasted):  # missed this frame but likely still there: the predicted box, no detection
            shown = np.concatenate([shown, coasted])
            original = np.concatenate([original, np.full(len(coasted), -1)])
            boxes = np.vstack([boxes, _to_xywh(self._mean[coasted, :4])])
        velocity = self._mean[shown, 4:6] / self._clock.interval
        return [
            TrackSnapshot(track_id=int(self._ids[i]), status=TrackStatus.CONFIRMED, xywh=np.array(boxes[j]),
                          velocity=velocity[j], detection_index=int(original[j]))
            for j, i in enumerate(shown)
        ]

    def _prune(self) -> None:
        cfg = self.config
        closed = cfg.max_targets is not None
        alive = (self._lost_s == 0) | (self._confirmed & ((self._lost_s <= cfg.max_age_s) | closed))
        if alive.all():
            return
        self._mean, self._cov = self._mean[alive], self._cov[alive]
        gone = ~alive & self._confirmed
        self._misses.died(self._missed[gone])
        self._ids, self._hits, self._missed = self._ids[alive], self._hits[alive], self._missed[alive]
        self._lost_s, self._confirmed = self._lost_s[alive], self._confirmed[alive]
