"""The plain BoxTrack (as of commit 8cb920a): the oracle the columnar :class:`BoxTrack` must equal.

One track table with full ``(k, 8, 8)`` covariances, one closure per association stage costing every
eligible pair, the clutter share on its own IoU matrix. Frozen here so that
tests/test_boxtrack_fast.py can check the fast tracker gives the same rows, bit for bit.
"""

from __future__ import annotations

import numpy as np

from lookalike.association.costs import centre_distance_cost, cost_from_iou
from lookalike.association.stages import CostFn, Matching, Stage, run_plan
from lookalike.geometry.boxes import iou_matrix
from lookalike.motion.spaces import BoxCXCYWH, cxcywh_to_xywh
from lookalike.trackers import boxtrack_config as const
from lookalike.trackers.boxtrack_config import BoxTrackConfig
from lookalike.trackers.parts.closed_slots import ClosedSlots
from lookalike.trackers.parts.clutter import ClutterShare
from lookalike.trackers.parts.coasting import Coasting
from lookalike.trackers.parts.lifecycle import Lifecycle
from lookalike.trackers.parts.motion_fit import MotionFit
from lookalike.trackers.parts.self_calibration import ScoreCalibration
from lookalike.trackers.parts.table import TrackTable
from lookalike.trackers.parts.timing import FrameClock
from lookalike.types import Frame, Tracks


class PlainBoxTrack:
    """Motion-only box tracker: score-split association, motion re-identification, closed sets."""

    Config = BoxTrackConfig

    def __init__(self, config: BoxTrackConfig | None = None, *, vel_noise: float | None = None) -> None:
        """``vel_noise``: the velocity's process noise per frame as a fraction of the box size (default
        ``boxtrack_config.VEL_NOISE``). Not a parameter of the tracker: a hook for inputs whose boxes are
        not objects' extents (anonymous points as boxes, :data:`lookalike.io.points.POINT_VEL_NOISE`)."""
        self.config = cfg = config or BoxTrackConfig()
        if vel_noise is not None and not vel_noise > 0:
            raise ValueError(f"vel_noise must be > 0, got {vel_noise}")
        self._space = BoxCXCYWH(const.POS_NOISE, const.VEL_NOISE if vel_noise is None else float(vel_noise))
        lifecycle = Lifecycle(n_init=cfg.n_init, tentative_max_misses=None, tentative_max_unseen_s=0.0,
                              max_unseen_s=cfg.max_age_s)
        self._lifecycle = lifecycle.closed_set() if cfg.max_targets is not None else lifecycle
        self._slots = None if cfg.max_targets is None else ClosedSlots(
            cfg.max_targets, cfg.closed_distance, const.CLOSED_GATE_GROWTH, refill_s=cfg.max_age_s)
        self.reset()

    def reset(self) -> None:
        """Forget every track; ids restart at 1."""
        cfg = self.config
        self._tracks = TrackTable(8)
        self._frame_count = 0
        self._clock = FrameClock(cfg.frame_interval_s)
        self._calibration = ScoreCalibration(
            cfg.high_score, cfg.birth_score, high_quantile=const.HIGH_QUANTILE, high_match_ratio=cfg.high_match_ratio,
            calib_min_count=const.CALIB_MIN_COUNT, clutter_factor=cfg.clutter_factor, clutter_floor=const.CLUTTER_FLOOR)
        self._clutter = ClutterShare(const.CLUTTER_IOU, const.CLUTTER_MIN_COUNT)
        self._coasting = Coasting(const.COAST_S, const.COAST_REPORT_PROB, const.COAST_MIN_COUNT)
        self._fit = MotionFit(const.FIT_BATCH)
        self._scaled: tuple[float, BoxCXCYWH] | None = None  # (fit scale, the space with its noise)

    def update(self, frame: Frame) -> Tracks:
        """Advance all tracks to ``frame`` and match its detections."""
        cfg, t = self.config, self._tracks
        steps = self._clock.steps(frame.time)
        dt = steps * self._clock.interval
        self._frame_count += 1
        dets = frame.detections
        keep = dets.score >= cfg.low_score
        if keep.all():  # the read-only columns themselves, no copies
            det_idx, det_xywh, score = np.arange(len(keep)), dets.xywh, dets.score
        else:
            det_idx = keep.nonzero()[0]
            det_xywh, score = dets.xywh[det_idx], dets.score[det_idx]
        det_box = self._space.measure(det_xywh)
        self._calibration.observe_scores(score)
        self._clutter.observe(det_xywh)
        high_score, birth_score, _ = self._calibration.decide(self._clutter.share)
        was_tracked = t.unseen_s == 0
        if len(t):
            if self._slots is not None:
                self._slots.freeze_shape(t)
            t.mean[self._coasting.still(t.unseen_s), 4:] = 0.0  # a long-lost track waits where it was last seen
            t.mean, t.cov = self._predict_space().predict(t.mean, t.cov, steps)
        matching = self._associate(det_xywh, det_box, score, high_score, was_tracked,
                                   t.unseen_s + dt)
        det_of_track, free = matching.det_of_track, matching.free
        hit = det_of_track >= 0
        matched = hit.nonzero()[0]
        if len(matched):
            d = det_of_track[matched]
            z = det_box[d]
            conf = t.confirmed[matched]
            self._observe_fit(matched[conf], z[conf])
            if len(matched) == len(t):  # every track matched: no gather and scatter
                t.mean, t.cov = self._space.update(t.mean, t.cov, z)
            else:
                t.mean[matched], t.cov[matched] = self._space.update(t.mean[matched], t.cov[matched], z)
            t.hits[matched] += 1
            back = matched[conf & (t.misses[matched] > 0)]
            if len(back):
                self._coasting.observe(came_back=t.misses[back])
        np.multiply(t.hits, hit, out=t.hits)  # a miss resets the hit count
        if self._slots is not None:
            self._slots.observe_speed(t, hit, self._clock.interval)
        t.record(hit, dt)
        ready = t.hits >= cfg.n_init
        if self._frame_count == 1:
            ready |= t.hits > 0
        if self._slots is None:
            t.confirmed |= ready
        else:
            det_of_track = self._slots.refill(t, ready, det_of_track)
        born = self._births(np.flatnonzero(free & (score >= birth_score)), det_box)
        out = self._report(np.concatenate([det_of_track, born]), det_idx, dets.xywh)
        alive = self._lifecycle.alive(t)
        if not alive.all():
            self._coasting.observe(died=t.misses[~alive & t.confirmed])
            t.keep(alive)
        return out

    def _associate(self, det_xywh: np.ndarray, det_box: np.ndarray, score: np.ndarray, high_score: float,
                   was_tracked: np.ndarray, unseen_s: np.ndarray) -> Matching:
        """The association plan: confident detections to confirmed tracks (recent ones first), low-score
        ones to tracks seen last frame, the rest to tentative tracks, then lost tracks by centre distance."""
        cfg, t = self.config, self._tracks
        high = score >= high_score
        # one IoU matrix per frame; each stage takes its block of it
        iou = iou_matrix(cxcywh_to_xywh(t.mean[:, :4]), det_xywh) if len(t) and len(score) else None

        def overlap(min_iou: float, weigh: bool) -> CostFn:
            return lambda r, c: cost_from_iou(iou[r[:, None], c], min_iou,  # type: ignore[index]
                                              score[c] if weigh else None)

        recent = t.misses <= const.RECENT_FRAMES
        matching = run_plan([
            Stage(t.confirmed & recent, high, overlap(cfg.match_iou, True), name="confident, recent"),
            Stage(t.confirmed & ~recent, high, overlap(cfg.match_iou, True), name="confident, lost longer"),
            Stage(t.confirmed & was_tracked, ~high, overlap(const.LOW_IOU, False), name="low score"),
        ], len(t), len(score))
        self._calibration.observe_continued(score, matching.det_of_track[matching.det_of_track >= 0])
        stages = [Stage(~t.confirmed, high, overlap(cfg.match_iou, False), name="tentative")]
        slots = self._slots

        def reid(r: np.ndarray, c: np.ndarray) -> np.ndarray:
            # built only when some lost track and confident detection are left
            if slots is not None:  # closed set: sizes as sqrt(w·h), a turning target keeps its size; gates in heights
                track_box, box = slots.squared(t.mean[:, :4]), slots.squared(det_box)
                gate, scale = slots.gate(unseen_s), max(cfg.reid_scale, const.CLOSED_SCALE)
            else:  # in fitted standard deviations: a model that fits badly (MotionFit) widens the gate
                track_box, box, scale = t.mean[:, :4], det_box, cfg.reid_scale
                gate = np.full((len(t), 1), const.REID_DISTANCE * np.sqrt(self._fit.scale))
            return centre_distance_cost(track_box[r], box[c], gate[r], scale)

        stages.append(Stage(t.confirmed, high, reid, name="re-identification"))
        return run_plan(stages, len(t), len(score), start=matching)

    def _predict_space(self) -> BoxCXCYWH:
        """The motion model with its process noise scaled by :class:`MotionFit` (variance factor)."""
        if self._fit.scale == 1.0:
            return self._space
        if self._scaled is None or self._scaled[0] != self._fit.scale:
            r = float(np.sqrt(self._fit.scale))
            self._scaled = (self._fit.scale, BoxCXCYWH(self._space.pos_noise * r, self._space.vel_noise * r))
        return self._scaled[1]

    def _observe_fit(self, tracks: np.ndarray, z: np.ndarray) -> None:
        """Centre innovations of confirmed ``tracks`` against their detections ``z`` (cx, cy, w, h)."""
        if len(tracks):
            t = self._tracks
            cov = t.cov[tracks, :2, :2]
            noise = self._space.pos_noise * z[:, 2:4]
            noise *= noise  # the measurement variances of cx and cy, the diagonal of R
            self._fit.observe_parts(z[:, :2] - t.mean[tracks, :2], cov[:, 0, 0] + noise[:, 0],
                                    cov[:, 0, 1] + 0.0, cov[:, 1, 1] + noise[:, 1])

    def _births(self, new: np.ndarray, det_box: np.ndarray) -> np.ndarray:
        """Start tentative tracks on detections ``new``; returns the detections used."""
        cfg, t = self.config, self._tracks
        if self._slots is not None:
            new = new[: self._slots.room(t)]
        if len(new):
            mean, cov = self._space.initial(det_box[new])
            first = self._frame_count == 1
            t.add(mean, cov, hits=1, confirmed=first or (cfg.n_init <= 1 and self._slots is None))
        return new

    def _report(self, det_of_track: np.ndarray, det_idx: np.ndarray, det_xywh: np.ndarray) -> Tracks:
        t = self._tracks
        shown = np.flatnonzero(t.confirmed & (t.unseen_s == 0) & (det_of_track >= 0))
        missed = (t.confirmed & (det_of_track < 0)).nonzero()[0]
        coasted = missed[self._coasting.decide(t.misses[missed])] if len(missed) else missed
        original = det_idx[det_of_track[shown]]
        if len(coasted):  # missed this frame but likely still there: the predicted box, no detection
            shown = np.concatenate([shown, coasted])
            original = np.concatenate([original, np.full(len(coasted), -1)])
        boxes = cxcywh_to_xywh(t.mean[shown, :4])
        return Tracks.trusted(t.ids[shown], np.ones(len(shown), dtype=np.int8), boxes,
                              t.mean[shown, 4:6] / self._clock.interval, original)
