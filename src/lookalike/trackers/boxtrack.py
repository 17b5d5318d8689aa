"""BoxTrack: a motion-only box tracker for look-alike targets (no appearance), composed of the parts in
:mod:`lookalike.trackers.parts` (states :class:`~lookalike.motion.spaces.BoxCXCYWH` in pixels and pixels/frame).

Each frame: detections below ``low_score`` are dropped; confirmed tracks take confident detections on ``1 - IoU·score``
(recently seen first), tracks seen last frame take low-score ones on IoU, tentative tracks take the rest on IoU, and
lost tracks take what confident detections remain on centre distance. Left-over detections above the birth threshold
start tentative tracks. Reported: confirmed tracks matched this frame (filtered box) and confirmed tracks likely still
present (predicted box, ``detection_index`` -1). Mechanisms and defaults: docs/trackers/boxtrack.md.

States live in one quantity-major ``(24, k)`` column table (the track table's ``mean`` and ``cov`` are views of it).
With numba installed, frames run the compiled kernels of :mod:`lookalike.trackers.kernels.boxtrack` once loading
them pays, with the same numbers as the numpy path."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from lookalike.association.costs import centre_distance_cost, cost_from_iou, iou_columns
from lookalike.association.stages import CostFn, Matching, Stage, run_plan, run_stage
from lookalike.motion.spaces import BoxCXCYWH
from lookalike.trackers import boxtrack_config as const
from lookalike.trackers.boxtrack_config import BoxTrackConfig
from lookalike.trackers.kernels import boxtrack as boxtrack_kernels
from lookalike.trackers.parts.batches import near_pairs, overlapping_pairs, run_in_batches
from lookalike.trackers.parts.closed_slots import ClosedSlots
from lookalike.trackers.parts.clutter import ClutterShare
from lookalike.trackers.parts.coasting import Coasting
from lookalike.trackers.parts.lifecycle import Lifecycle
from lookalike.trackers.parts.motion_fit import MotionFit
from lookalike.trackers.parts.self_calibration import ScoreCalibration
from lookalike.trackers.parts.table import TrackTable
from lookalike.trackers.parts.timing import FrameClock
from lookalike.trackers.registry import register_tracker
from lookalike.types import Detections, Frame, Tracks

_NO_BOXES = np.zeros((0, 4))
_NO_INDEX = np.zeros(0, dtype=np.int64)
_F64 = np.dtype(np.float64)
LARGE_PAIRS = 1 << 20  # frames with more (track + previous box) × detection pairs are associated in batches


@register_tracker("boxtrack")
class BoxTrack:
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
        self._path = boxtrack_kernels.PathChoice(allowed=cfg.match_iou > 0)  # (the kernels need IoU gates)
        self.reset()

    def expect(self, frames: int) -> None:
        """A hint that about ``frames`` frames follow (:func:`lookalike.trackers.kernels.boxtrack.expect`)."""
        self._path.expect(frames)

    def reset(self) -> None:
        """Forget every track; ids restart at 1."""
        cfg = self.config
        self._tracks = TrackTable(8, cov_shape=(4, 4))  # cov: the 2×2-block diagonals [p11, p12, p21, p22]
        self._columns = np.zeros((24, 0))  # BoxCXCYWH's column form; mean and cov are its views (_state)
        self._views: tuple[np.ndarray | None, np.ndarray | None] = (None, None)
        self._frame_count = 0
        self._clock = FrameClock(cfg.frame_interval_s)
        self._slots = None if cfg.max_targets is None else ClosedSlots(  # (it learns the slots' typical speed)
            cfg.max_targets, cfg.closed_distance, const.CLOSED_GATE_GROWTH, refill_s=cfg.max_age_s)
        self._calibration = ScoreCalibration(
            cfg.high_score, cfg.birth_score, high_quantile=const.HIGH_QUANTILE, high_match_ratio=cfg.high_match_ratio,
            calib_min_count=const.CALIB_MIN_COUNT, clutter_factor=cfg.clutter_factor, clutter_floor=const.CLUTTER_FLOOR)
        self._clutter = ClutterShare(const.CLUTTER_IOU, const.CLUTTER_MIN_COUNT)
        self._coasting = Coasting(const.COAST_S, const.COAST_REPORT_PROB, const.COAST_MIN_COUNT)
        self._fit = MotionFit(const.FIT_BATCH)
        self._scaled: tuple[float, BoxCXCYWH] | None = None  # (fit scale, the space with its noise)
        self._buffers = (np.empty((4, 16)), np.empty(16, dtype=np.int64))  # the compiled update's outputs
        self._never = np.zeros(self._coasting.returns.longest + 2, dtype=bool)  # no coasted report

    def __setstate__(self, state: dict[str, Any]) -> None:
        """After ``copy.deepcopy`` or unpickling, the table's ``mean`` and ``cov`` are copies, no longer views of
        the column table: forget the link so that the next frame rebuilds the table from them."""
        self.__dict__.update(state)
        self._views = (None, None)

    @property
    def compiled(self) -> bool:
        """Whether this tracker runs the compiled kernels (:mod:`lookalike.trackers.kernels.boxtrack`) now."""
        return bool(self._path.kernels)

    def update(self, frame: Frame) -> Tracks:
        """Advance all tracks to ``frame`` and match its detections."""
        dets = frame.detections
        if self._path.kernels and dets.xywh.dtype is _F64 and dets.score.dtype is _F64 and not self._large(len(dets)):
            # (float64 columns, as Detections makes them: the kernels' arithmetic is the numpy path's; the
            # module is looked up, not kept, so the tracker stays picklable)
            return self._update_compiled(frame, boxtrack_kernels.module())
        return self._path.numpy(self._update_numpy, frame)

    def _update_numpy(self, frame: Frame) -> Tracks:
        t, clock = self._tracks, self._clock
        steps, dt, det_xywh, score, det_idx, x = self._begin(frame)
        z = BoxCXCYWH.measure_columns(det_xywh.T)
        was_tracked = t.unseen_s == 0
        if len(t):
            if self._slots is not None:
                self._slots.freeze_shape(t)
            still = self._coasting.still(t.unseen_s)
            if np.count_nonzero(still):
                x[4:8, still] = 0.0  # a long-lost track waits where it was last seen
            self._predict_space().predict_columns(x, steps)
        if self._large(len(score)):
            self._clutter.observe_pairs(det_xywh)
            high_score, birth_score, _ = self._calibration.decide(self._clutter.share)
            matching = self._associate_batches(x, det_xywh, z.T, score, high_score, was_tracked, dt)
        else:
            iou, low_gate = self._overlaps(x, det_xywh)
            high_score, birth_score, _ = self._calibration.decide(self._clutter.share)
            matching = self._associate(iou, low_gate, z.T, score, high_score, was_tracked, dt)
        det_of_track, free = matching.det_of_track, matching.free
        hit = det_of_track >= 0
        matched = hit.nonzero()[0]
        if len(matched):
            self._correct(x, matched, z[:, det_of_track[matched]])
        np.add(t.hits, hit, out=t.hits)
        np.multiply(t.hits, hit, out=t.hits)  # one more hit for the matched tracks; a miss resets the count
        if self._slots is not None:
            self._slots.observe_speed(t, hit, clock.interval)
        t.record(hit, dt)
        ready = self._ready()
        if self._slots is None:
            t.confirmed |= ready
        else:
            det_of_track = self._slots.refill(t, ready, det_of_track)
        born = self._births((free & (score >= birth_score)).nonzero()[0], z)
        out = self._report(np.concatenate((det_of_track, born)) if len(born) else det_of_track, det_idx)
        alive = self._lifecycle.alive(t)
        if np.count_nonzero(alive) < len(alive):
            self._coasting.observe(died=t.misses[~alive & t.confirmed])
            t.keep(alive)
        return out

    def _begin(self, frame: Frame) -> tuple[float, float, np.ndarray, np.ndarray, np.ndarray | None, np.ndarray]:
        """A frame's first steps on either path: its time steps and seconds since the last frame, the kept
        detections (:meth:`_kept`, their scores observed) and the tracks' state table (:meth:`_state`)."""
        steps = self._clock.steps(frame.time)
        dt = steps * self._clock.interval
        self._frame_count += 1
        det_xywh, score, det_idx = self._kept(frame.detections)
        self._calibration.observe_scores(score)
        return steps, dt, det_xywh, score, det_idx, self._state()

    def _ready(self) -> np.ndarray:
        """The tracks with ``n_init`` hits in a row, or any hit in the first frame: ready to confirm."""
        ready = self._tracks.hits >= self.config.n_init
        if self._frame_count == 1:
            ready |= self._tracks.hits > 0
        return ready

    def _observe_continued(self, score: np.ndarray, matching: Matching) -> None:
        """Show the score calibration the detections that continued confirmed tracks in the first three
        stages (the later two change no earlier match)."""
        first_three = matching.stage_of_track.view(np.uint64) < 3  # stages 0-2 (unmatched -1: beyond, as unsigned)
        self._calibration.observe_continued(score, matching.det_of_track[first_three])

    def _kept(self, dets: Detections) -> tuple[np.ndarray, np.ndarray, np.ndarray | None]:
        """The detections scoring at least ``low_score``: their boxes ``(n, 4)`` (left, top, width, height;
        pixels), scores, and their indices in the frame (None: every detection kept, at its own index; then the
        columns are the read-only ones of ``dets``, no copies)."""
        det_xywh, score = dets.xywh, dets.score
        det_idx = None
        if len(score) and np.count_nonzero(score < self.config.low_score):
            det_idx = (score >= self.config.low_score).nonzero()[0]
            det_xywh, score = det_xywh[det_idx], score[det_idx]
        return det_xywh, score, det_idx

    def _update_compiled(self, frame: Frame, kern: Any) -> Tracks:
        """:meth:`update` with the compiled kernels: the same steps and numbers as the numpy path."""
        cfg, t, clock = self.config, self._tracks, self._clock
        steps, dt, det_xywh, score, det_idx, x = self._begin(frame)
        if self._slots is not None and len(t):
            self._slots.freeze_shape(t)
        space, clutter = self._predict_space(), self._clutter
        previous = clutter.previous
        iou, flicker = kern.advance(x, steps, max(steps, 0.0), t.unseen_s, self._coasting.coast_s,
                                    space.pos_noise**2, space.vel_noise**2,
                                    _NO_BOXES if previous is None else previous, det_xywh, clutter.min_iou)
        clutter.observe_count(det_xywh, flicker)
        high_score, birth_score, _ = self._calibration.decide(clutter.share)
        k, n = iou.shape
        matching = Matching.empty(k, n)
        if k and n:
            self._associate_compiled(kern, iou, det_xywh, score, high_score, dt, matching)
        self._observe_continued(score, matching)
        det_of_track = matching.det_of_track
        fit, back = self._buffers
        if fit.shape[1] < k:
            fit, back = self._buffers = (np.empty((4, 2 * k)), np.empty(2 * k, dtype=np.int64))
        slots = self._slots
        n_fit, n_back = kern.correct(x, det_of_track, det_xywh, self._space.pos_noise, t.confirmed, t.misses,
                                     t.unseen_s, t.hits, slots is None, dt, cfg.n_init, self._frame_count == 1,
                                     fit, back)
        if n_fit:
            self._fit.observe_columns(fit[0:2, :n_fit], fit[2:4, :n_fit])
        if n_back:
            self._coasting.observe(came_back=back[:n_back])
        if slots is not None:
            hit = det_of_track >= 0
            slots.observe_speed(t, hit, clock.interval)
            t.record(hit, dt)
            det_of_track = slots.refill(t, self._ready(), det_of_track)
        new = (matching.free & (score >= birth_score)).nonzero()[0]
        born = self._births(new, BoxCXCYWH.measure_columns(det_xywh.T) if len(new) else _NO_BOXES.T)
        coasting, life = self._coasting, self._lifecycle
        present = self._never if coasting.report_prob is None else coasting.returns.present_table(
            coasting.report_prob, coasting.min_count)
        alive = np.empty(len(t), dtype=bool)
        ids, status, boxes, velocity, original, n_alive = kern.report(
            t.mean, t.ids, t.confirmed, det_of_track, born, _NO_INDEX if det_idx is None else det_idx, t.misses,
            present, clock.interval, t.unseen_s, life.tentative_max_unseen_s, life.max_unseen_s, life.closed, alive)
        out = Tracks.trusted(ids, status, boxes, velocity, original)
        if n_alive < len(alive):
            coasting.observe(died=t.misses[~alive & t.confirmed])
            t.keep(alive)
        return out

    def _associate_compiled(self, kern: Any, iou: np.ndarray, det_xywh: np.ndarray, score: np.ndarray,
                            high_score: float, dt: float, matching: Matching) -> None:
        """:meth:`_associate`'s plan with the IoU stages compiled; a stage whose allowed pairs compete, and
        the re-identification stage when it has candidates, run as in the numpy path."""
        cfg, t = self.config, self._tracks
        args = (cfg.match_iou, const.LOW_IOU, t.confirmed, t.misses, const.RECENT_FRAMES, t.unseen_s, score,
                high_score, matching.det_of_track, matching.free, matching.stage_of_track)
        stage = kern.gated_stages(iou, 0, *args)
        if stage > 4:
            return
        det_box = BoxCXCYWH.measure_columns(det_xywh.T).T
        if stage < 4:
            stages = self._plan(iou, None, det_box, score, high_score, t.unseen_s == 0, dt)
            while stage < 4:  # competing pairs: this stage's costs decide
                run_stage(stages[stage]._replace(gate=None), matching, stage)
                stage = kern.gated_stages(iou, stage + 1, *args)
        if stage == 4:
            run_stage(Stage(t.confirmed, score >= high_score, self._reid(det_box, dt), name="re-identification"),
                      matching, 4)

    def _state(self) -> np.ndarray:
        """The tracks' states as :class:`BoxCXCYWH`'s column table ``(24, k)``, of which the track table's
        ``mean`` and ``cov`` are views; rebuilt from the table after it added or removed rows."""
        t = self._tracks
        if t.mean is not self._views[0] or t.cov is not self._views[1]:
            k = len(t)
            x = np.empty((24, k))
            x[:8] = t.mean.T
            x[8:] = t.cov.reshape(k, 16).T
            t.mean, t.cov = x[:8].T, x[8:].T.reshape(k, 4, 4)
            self._columns, self._views = x, (t.mean, t.cov)
        return self._columns

    def _overlaps(self, x: np.ndarray, det_xywh: np.ndarray) -> tuple[np.ndarray | None, np.ndarray | None]:
        """One IoU matrix of the predicted track boxes (state columns ``x``) and the previous frame's
        detections (rows) against this frame's detections (columns): the clutter share counts from the
        second block. Returns the first ``(k, n)`` (None without tracks or detections) and, when the
        low-score stage and the clutter share use the same IoU, its pairs reaching it (else None)."""
        clutter = self._clutter
        previous = clutter.previous
        k, n, p = x.shape[1], len(det_xywh), 0 if previous is None else len(previous)
        if not n or not (k or p):
            clutter.observe_overlaps(det_xywh, None)
            return None, None
        boxes = np.empty((4, k + p))  # left, top, width, height as columns
        if k:  # the predicted boxes
            BoxCXCYWH.box_columns(x, boxes[:, :k])
        if p:
            boxes[:, k:] = previous.T  # type: ignore[union-attr]
        iou = iou_columns(boxes, det_xywh.T)
        shared = const.LOW_IOU == clutter.min_iou
        overlap = iou >= clutter.min_iou if p or shared else None
        clutter.observe_overlaps(det_xywh, overlap[k:] if p else None)  # type: ignore[index]
        if not k:
            return None, None
        return iou[:k], overlap[:k] if shared else None  # type: ignore[index]

    def _large(self, n: int) -> bool:
        """Whether a frame of ``n`` detections is associated in batches (:meth:`_associate_batches`): more than
        :data:`LARGE_PAIRS` pairs with the tracks and the previous frame's boxes, and IoU gates that split it."""
        previous = self._clutter.previous
        pairs = (len(self._tracks) + (0 if previous is None else len(previous))) * n
        return pairs > LARGE_PAIRS and self.config.match_iou > 0

    def _associate_batches(self, x: np.ndarray, det_xywh: np.ndarray, det_box: np.ndarray, score: np.ndarray,
                           high_score: float, was_tracked: np.ndarray, dt: float) -> Matching:
        """:meth:`_associate` of a large frame, in memory linear in its boxes: the plan runs on batches of the
        connected groups of tracks and detections that overlap or lie within re-identification reach
        (:mod:`~lookalike.trackers.parts.batches`); no stage can match across groups, so the matches are the same."""
        k = x.shape[1]
        boxes = np.empty((4, k))
        BoxCXCYWH.box_columns(x, boxes)
        i, j = overlapping_pairs(boxes.T, det_xywh)
        track_box, gate, _ = self._reid_gate(dt)
        radius = np.ravel(gate * np.maximum(track_box[:, 3:4], 1.0)) * (1 + 1e-9)  # (a hair wide: no pair too few)
        radius[~self._tracks.confirmed] = np.nan  # only confirmed tracks are re-identified
        ri, rj = near_pairs(track_box[:, :2], radius, det_box[:, :2])

        def plan(rows: np.ndarray, cols: np.ndarray) -> list[Stage]:
            iou = iou_columns(boxes[:, rows], det_xywh[cols].T)
            return self._plan(iou, None, det_box[cols], score[cols], high_score, was_tracked[rows], dt, rows)

        matching = run_in_batches(k, len(score), np.concatenate((i, ri)), np.concatenate((j, rj)), LARGE_PAIRS, plan)
        self._observe_continued(score, matching)
        return matching

    def _associate(self, iou: np.ndarray | None, low_gate: np.ndarray | None, det_box: np.ndarray,
                   score: np.ndarray, high_score: float, was_tracked: np.ndarray, dt: float) -> Matching:
        """The association plan: confident detections to confirmed tracks (recent ones first), low-score
        ones to tracks seen last frame, the rest to tentative tracks, then lost tracks by centre distance."""
        matching = run_plan(self._plan(iou, low_gate, det_box, score, high_score, was_tracked, dt),
                            len(self._tracks), len(score))
        self._observe_continued(score, matching)
        return matching

    def _plan(self, iou: np.ndarray | None, low_gate: np.ndarray | None, det_box: np.ndarray, score: np.ndarray,
              high_score: float, was_tracked: np.ndarray, dt: float, rows: np.ndarray | None = None) -> list[Stage]:
        """:meth:`_associate`'s stages: IoU ``iou (k, n)`` of the predicted boxes and the detections (None
        without either), ``low_gate`` its pairs reaching ``LOW_IOU`` (None: computed here), ``det_box (n, 4)``
        the detections' cx, cy, w, h (pixels); ``rows``: the tracks of a batch (None: all)."""
        cfg, t = self.config, self._tracks
        high = score >= high_score
        # each IoU stage takes its block of the frame's matrix; it allows the pairs reaching its IoU
        match_gate = None
        if iou is not None:
            if low_gate is None:
                low_gate = iou >= const.LOW_IOU
            if cfg.match_iou > 0:  # else every pair is allowed: the costs decide
                match_gate = low_gate if cfg.match_iou == const.LOW_IOU else iou >= cfg.match_iou

        def overlap(min_iou: float, weigh: bool) -> CostFn:
            return lambda r, c: cost_from_iou(iou[r[:, None], c], min_iou,  # type: ignore[index]
                                              score[c] if weigh else None)

        confirmed, misses = (t.confirmed, t.misses) if rows is None else (t.confirmed[rows], t.misses[rows])
        recent = misses <= const.RECENT_FRAMES
        reid = self._reid(det_box, dt, rows)
        return [
            Stage(confirmed & recent, high, overlap(cfg.match_iou, True), name="confident, recent", gate=match_gate),
            Stage(confirmed > recent, high, overlap(cfg.match_iou, True), name="confident, lost longer",
                  gate=match_gate),  # (confirmed and not recent)
            Stage(confirmed & was_tracked, ~high, overlap(const.LOW_IOU, False), name="low score", gate=low_gate),
            Stage(~confirmed, high, overlap(cfg.match_iou, False), name="tentative", gate=match_gate),
            Stage(confirmed, high, reid, name="re-identification"),
        ]

    def _reid(self, det_box: np.ndarray, dt: float, rows: np.ndarray | None = None) -> CostFn:
        """The re-identification stage's cost of lost tracks and detections ``det_box (n, 4)`` (cx, cy, w, h;
        pixels), ``dt`` seconds after the tracks' last frame; ``rows``: the tracks of a batch (None: all)."""
        slots = self._slots

        def reid(r: np.ndarray, c: np.ndarray) -> np.ndarray:
            # built only when some lost track and confident detection are left
            track_box, gate, scale = self._reid_gate(dt)
            r = r if rows is None else rows[r]
            box = det_box if slots is None else slots.squared(det_box)
            return centre_distance_cost(track_box[r], box[c], gate[r] if isinstance(gate, np.ndarray) else gate, scale)

        return reid

    def _reid_gate(self, dt: float) -> tuple[np.ndarray, np.ndarray | float, float]:
        """Re-identification's terms for every track: its box (cx, cy, w, h; closed set: a square of the same area, so
        a turning target keeps its size), its gate in box heights (``(k, 1)``, or one for all) and the largest size
        ratio. Open set: in fitted standard deviations, so a model that fits badly (MotionFit) widens the gate."""
        cfg, t, slots = self.config, self._tracks, self._slots
        if slots is not None:
            return slots.squared(t.mean[:, :4]), slots.gate(t.unseen_s + dt), max(cfg.reid_scale, const.CLOSED_SCALE)
        return t.mean[:, :4], const.REID_DISTANCE * math.sqrt(self._fit.scale), cfg.reid_scale

    def _correct(self, x: np.ndarray, matched: np.ndarray, z: np.ndarray) -> None:
        """Kalman update of the tracks ``matched`` (columns of ``x``) with their measurements ``z (4, m)``; the centre
        innovations of the confirmed ones go to :class:`MotionFit`, their returns after misses to :class:`Coasting`."""
        t, space = self._tracks, self._space
        every = len(matched) == x.shape[1]  # every track matched: no gather and scatter
        sub = x if every else x.take(matched, axis=1)
        innovation, s = space.innovation_columns(sub, z)
        confirmed = t.confirmed[matched]
        self._fit.observe_columns(innovation[0:2], s[0:2], confirmed)
        space.correct_columns(sub, innovation, s)
        if not every:
            x[:, matched] = sub
        misses = t.misses[matched]
        if np.count_nonzero(misses):
            back = confirmed & (misses > 0)
            if np.count_nonzero(back):
                self._coasting.observe(came_back=misses[back])

    def _predict_space(self) -> BoxCXCYWH:
        """The motion model with its process noise scaled by :class:`MotionFit` (variance factor)."""
        if self._fit.scale == 1.0:
            return self._space
        if self._scaled is None or self._scaled[0] != self._fit.scale:
            r = float(np.sqrt(self._fit.scale))
            self._scaled = (self._fit.scale, BoxCXCYWH(self._space.pos_noise * r, self._space.vel_noise * r))
        return self._scaled[1]

    def _births(self, new: np.ndarray, z: np.ndarray) -> np.ndarray:
        """Start tentative tracks on detections ``new`` (measurement columns ``z``); returns the detections used."""
        cfg, t = self.config, self._tracks
        if self._slots is not None:
            new = new[: self._slots.room(t)]
        if len(new):
            rows = self._space.initial_rows(z[:, new].T)
            first = self._frame_count == 1
            t.add(rows[:, :8], rows[:, 8:].reshape(-1, 4, 4), hits=1,
                  confirmed=first or (cfg.n_init <= 1 and self._slots is None))
        return new

    def _report(self, det_of_track: np.ndarray, det_idx: np.ndarray | None) -> Tracks:
        """Confirmed tracks matched this frame at their filtered box, then confirmed tracks likely still
        present at their predicted box (detection index -1); ``det_idx``: the kept detections' indices
        in the frame (None: all kept)."""
        t = self._tracks
        confirmed, hit = t.confirmed, det_of_track >= 0  # (a track with a detection was seen this frame)
        shown = (confirmed & hit).nonzero()[0]
        original = det_of_track[shown]
        if det_idx is not None:
            original = det_idx[original]
        missed = (confirmed > hit).nonzero()[0]  # confirmed and missed
        if len(missed):
            coasted = missed[self._coasting.decide(t.misses[missed])]
            if len(coasted):  # missed this frame but likely still there: the predicted box, no detection
                shown = np.concatenate((shown, coasted))
                original = np.concatenate((original, np.full(len(coasted), -1)))
        m = len(shown)
        x = t.mean.T[:6].take(shown, axis=1)  # box and velocity rows (after births, not yet a view of _columns)
        boxes, velocity, status = np.empty((m, 4)), np.empty((m, 2)), np.empty(m, dtype=np.int8)
        BoxCXCYWH.box_columns(x, boxes.T)
        np.divide(x[4:6], self._clock.interval, out=velocity.T)
        status.fill(1)
        return Tracks.trusted(t.ids[shown], status, boxes, velocity, original)
