"""HOG cascade detector: a pool of variable-size HOG blocks, discrete AdaBoost stages (each keeping ``stage_hit_rate``
of the positives, trained against mined hard negatives), slid over an image pyramid; the last-stage margin becomes a
probability, then NMS."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import asdict, dataclass, field
from pathlib import Path

import numpy as np

from lookalike._optional import needs
from lookalike.geometry.boxes import iou_matrix
from lookalike.types import Detections
from lookalike.vision.hog_blocks import (  # noqa: F401  (block_pool, window_features: part of this module's API)
    block_features_grid,
    block_features_rows,
    block_pool,
    cell_integral32,
    window_features,
)
from lookalike.vision.hog_features import BINS, as_bgr_image, cell_histograms, to_grey
from lookalike.vision.hog_kernels import compiled
from lookalike.vision.model_file import load_model_file, save_model_file
from lookalike.vision.nms import merge_nms, nms  # noqa: F401  (nms is part of this module's API)

FORMAT = "lookalike-hog-cascade"
VERSION = 2  # 2: target boxes less context_pad, merging NMS


@dataclass(frozen=True)
class CascadeConfig:
    """Training and detection settings; sizes in pixels."""

    window_px: tuple[int, int] = (32, 64)  # width, height
    cell_px: int = 4  # block positions and sizes are multiples of this
    stages: int = 20
    stage_hit_rate: float = 0.995
    max_stumps: int = 40
    negatives_per_stage: int = 2000
    max_draws_per_stage: int = 10  # hard-negative search: at most this many batches of negatives_per_stage windows
    min_hard_negatives: int = 20  # stop training when a stage's search finds fewer hard negatives than this
    target_false_positive_rate: float = 1e-4  # stop when the cascade accepts fewer background windows than this
    scale_step: float = 1.25
    min_height_px: float = 64.0  # = window height: the finest pyramid level is the image itself
    max_height_px: float = 320.0
    stride_cells: int = 2
    nms_overlap: float = 0.3  # suppress a window whose intersection with a better one exceeds this of the smaller
    merge_iou: float = 0.3  # a kept box is the mean of the windows overlapping it by more than this IoU
    context_pad: float = 0.1  # context around the target in training windows, a fraction of its height per side
    hard_negative_max_iou: float = 0.3  # scene mining: a window overlapping a true box more than this is no negative

    def __post_init__(self) -> None:
        w, h = self.window_px
        if w % self.cell_px or h % self.cell_px or w < 4 * self.cell_px or h < 4 * self.cell_px:
            raise ValueError(f"CascadeConfig.window_px: {self.window_px} must be multiples of cell_px and >= 4 cells")
        if not 1 <= self.stages <= 100:
            raise ValueError(f"CascadeConfig.stages: must be in 1..100, got {self.stages}")
        if not 0.5 < self.stage_hit_rate <= 1:
            raise ValueError(f"CascadeConfig.stage_hit_rate: must be in (0.5, 1], got {self.stage_hit_rate}")
        if self.negatives_per_stage < 1:
            raise ValueError(f"CascadeConfig.negatives_per_stage (--negatives): must be >= 1, got "
                             f"{self.negatives_per_stage}")
        if self.max_draws_per_stage < 1 or self.min_hard_negatives < 1:
            raise ValueError("CascadeConfig.max_draws_per_stage/min_hard_negatives: must be >= 1")
        if not 0 <= self.target_false_positive_rate < 1:
            raise ValueError(f"CascadeConfig.target_false_positive_rate: must be in [0, 1), got "
                             f"{self.target_false_positive_rate}")
        if not 0 <= self.context_pad < 1:
            raise ValueError(f"CascadeConfig.context_pad: must be in [0, 1), got {self.context_pad}")
        if not 0 <= self.hard_negative_max_iou < 1:
            raise ValueError(
                f"CascadeConfig.hard_negative_max_iou: must be in [0, 1), got {self.hard_negative_max_iou}"
            )
        if self.scale_step <= 1:
            raise ValueError(f"CascadeConfig.scale_step: must be > 1, got {self.scale_step}")


@dataclass
class Stage:
    """One boosted rejector: stumps on feature ``index`` (pooled descriptor column) at ``threshold``; each votes
    ``weight`` times +1 (above when ``sign`` is +1, below when -1) or -1; the stage accepts when the sum >= ``bias``."""

    index: np.ndarray
    threshold: np.ndarray
    sign: np.ndarray
    weight: np.ndarray
    bias: float

    def margin(self, features: np.ndarray) -> np.ndarray:
        return _margin(features[:, self.index], self)


@dataclass
class HogCascade:
    """A trained cascade; call it on an image to get :class:`Detections`."""

    config: CascadeConfig
    blocks: np.ndarray
    stages: list[Stage]
    calibration: tuple[float, float] = (1.0, 0.0)  # probability = sigmoid(a * last margin + b)
    _stage_blocks: list = field(default_factory=list, init=False, repr=False)

    def __post_init__(self) -> None:
        # Per stage: the blocks its stumps read, and each stump's column among those blocks' descriptors.
        self._stage_blocks = []
        for stage in self.stages:
            used = np.unique(stage.index // (4 * BINS))
            cols = np.searchsorted(used, stage.index // (4 * BINS)) * (4 * BINS) + stage.index % (4 * BINS)
            self._stage_blocks.append((self.blocks[used], cols))

    def classify(self, features: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``(accepted (n,) bool, last-stage margin (n,))`` for pooled descriptors ``(n, b * 36)``."""
        alive = np.ones(len(features), bool)
        margin = np.zeros(len(features))
        for stage in self.stages:
            idx = np.flatnonzero(alive)
            m = stage.margin(features[idx])
            margin[idx] = m
            alive[idx[m < stage.bias]] = False
        return alive, margin

    def windows(self, image: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Every pyramid window of a ``(h, w, 3)`` BGR or grey image that passes all stages, before non-maximum
        suppression: ``(xywh (n, 4) px, last-stage margin (n,))``."""
        with needs("cv2"):
            import cv2

        cfg = self.config
        img = np.asarray(image)
        grey = img.astype(np.float32) if img.ndim == 2 and img.dtype == np.float32 else to_grey(as_bgr_image(img))
        win_w, win_h = cfg.window_px
        step = cfg.stride_cells * cfg.cell_px
        # Per level the first stage on the whole window grid; later stages on the survivors of all levels at once.
        levels: list[tuple[float, int, np.ndarray, np.ndarray, np.ndarray]] = []  # scale, width, ox, oy, alive
        stacked: list[np.ndarray] = []  # each level's integral, one row of BINS values per corner
        first: list[np.ndarray] = []  # the first stage's margins of each level's windows that passed it
        scale = win_h / cfg.min_height_px
        while win_h / scale <= cfg.max_height_px:
            size = (int(round(grey.shape[1] * scale)), int(round(grey.shape[0] * scale)))
            if size[0] < win_w or size[1] < win_h:
                break
            level = grey if size == (grey.shape[1], grey.shape[0]) else cv2.resize(
                grey, size, interpolation=cv2.INTER_AREA if scale < 1 else cv2.INTER_LINEAR)
            # Integral over cells in (y, x, bin) order; float32 corners (rounding far below the stump thresholds).
            rows = cell_integral32(cell_histograms(level, cfg.cell_px).transpose(1, 2, 0))
            grid_y, grid_x = np.arange(0, size[1] - win_h + 1, step), np.arange(0, size[0] - win_w + 1, step)
            ox, oy = np.tile(grid_x, len(grid_y)), np.repeat(grid_y, len(grid_x))  # window origins (px), row by row
            if self.stages:
                stage, (used, columns) = self.stages[0], self._stage_blocks[0]
                if compiled() is not None:
                    features = block_features_rows(rows.reshape(-1, BINS), rows.shape[1], used, ox, oy, cfg.cell_px,
                                                   columns)
                else:
                    planes = np.ascontiguousarray(rows.transpose(2, 0, 1))
                    features = block_features_grid(planes, used, (len(grid_y), len(grid_x)), cfg.stride_cells,
                                                   cfg.cell_px, columns)
                margin = _margin(features, stage)
                alive = np.flatnonzero(margin >= stage.bias)
                first.append(margin[alive])
            else:
                alive = np.arange(len(ox))
                first.append(np.zeros(len(alive)))
            levels.append((scale, rows.shape[1], ox, oy, alive))
            stacked.append(rows.reshape(-1, BINS))
            scale /= cfg.scale_step
        if not levels:
            return np.zeros((0, 4)), np.zeros(0)
        corners = np.concatenate(stacked) if len(stacked) > 1 else stacked[0]
        offsets = np.cumsum([0] + [len(r) for r in stacked[:-1]])
        level_of = np.concatenate([np.full(len(a), i) for i, (_, _, _, _, a) in enumerate(levels)])
        ox = np.concatenate([x[a] for (_, _, x, _, a) in levels])
        oy = np.concatenate([y[a] for (_, _, _, y, a) in levels])
        width = np.array([w for (_, w, _, _, _) in levels])[level_of]
        margin = np.concatenate(first)
        for stage, (used, columns) in zip(self.stages[1:], self._stage_blocks[1:]):
            if not len(level_of):
                break
            cols = block_features_rows(corners, width, used, ox, oy, cfg.cell_px, columns, offsets[level_of])
            # One vote matrix per level (the sum's rounding may depend on the matrix).
            bounds = np.searchsorted(level_of, np.arange(len(levels) + 1))
            margin = np.concatenate([_margin(np.asfortranarray(cols[a:b]), stage)
                                     for a, b in zip(bounds[:-1], bounds[1:]) if b > a])
            keep = margin >= stage.bias
            level_of, ox, oy, width, margin = (v[keep] for v in (level_of, ox, oy, width, margin))
        if not len(level_of):
            return np.zeros((0, 4)), np.zeros(0)
        scales = np.array([sc for (sc, _, _, _, _) in levels])[level_of]
        boxes = np.column_stack([ox / scales, oy / scales, win_w / scales, win_h / scales])
        return boxes.astype(float), margin

    def target_boxes(self, windows_xywh: np.ndarray) -> np.ndarray:
        """Target boxes ``(n, 4)`` px of windows ``(n, 4)`` px: the window less its ``context_pad``, same centre."""
        w = np.asarray(windows_xywh, float).reshape(-1, 4)
        f = 1.0 / (1.0 + 2.0 * self.config.context_pad)
        cx, cy = w[:, 0] + w[:, 2] / 2, w[:, 1] + w[:, 3] / 2
        return np.column_stack([cx - w[:, 2] * f / 2, cy - w[:, 3] * f / 2, w[:, 2] * f, w[:, 3] * f])

    def boxes_and_margins(self, image: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Target boxes ``(n, 4)`` px after NMS, clipped to the image, and their windows' last-stage margins."""
        xywh, margins = self.windows(image)
        if not len(xywh):
            return np.zeros((0, 4)), np.zeros(0)
        a, b = self.calibration
        boxes, keep = merge_nms(self.target_boxes(xywh), a * margins + b, self.config.nms_overlap,
                                self.config.merge_iou)
        h, w = np.asarray(image).shape[:2]
        x0, y0 = np.clip(boxes[:, 0], 0, w), np.clip(boxes[:, 1], 0, h)  # the visible part of each box
        x1, y1 = np.clip(boxes[:, 0] + boxes[:, 2], 0, w), np.clip(boxes[:, 1] + boxes[:, 3], 0, h)
        boxes = np.column_stack([x0, y0, x1 - x0, y1 - y0])
        ok = (boxes[:, 2] > 0) & (boxes[:, 3] > 0)
        return boxes[ok], margins[keep][ok]

    def probability(self, margins: np.ndarray) -> np.ndarray:
        """Detection probability of last-stage ``margins``: ``sigmoid(a * margin + b)`` (:attr:`calibration`)."""
        a, b = self.calibration
        return 1.0 / (1.0 + np.exp(-(a * np.asarray(margins, float) + b)))

    def __call__(self, image: np.ndarray) -> Detections:
        """Detections (target boxes px, probability scores) in a ``(h, w, 3)`` BGR or grey image."""
        boxes, margins = self.boxes_and_margins(image)
        if not len(boxes):
            return Detections.empty()
        return Detections(xywh=boxes, score=self.probability(margins))

    detect = __call__

    def save(self, path: str | Path) -> Path:
        """Write the model to ``path`` (``.npz``) with its format name and version."""
        header = {"config": asdict(self.config), "calibration": list(self.calibration),
                  "biases": [s.bias for s in self.stages]}
        arrays = {"blocks": self.blocks}
        for k, s in enumerate(self.stages):
            arrays.update({f"s{k}_index": s.index, f"s{k}_threshold": s.threshold, f"s{k}_sign": s.sign,
                           f"s{k}_weight": s.weight})
        return save_model_file(path, FORMAT, VERSION, header, arrays)

    @classmethod
    def load(cls, path: str | Path) -> HogCascade:
        """Read a model written by :meth:`save`; a foreign, corrupt or newer file raises ``ValueError``."""
        header, arrays = load_model_file(path, FORMAT, VERSION, "HOG cascade model")
        try:
            cfg = header["config"]
            config = CascadeConfig(**{**cfg, "window_px": tuple(cfg["window_px"])})
            stages = [Stage(arrays[f"s{k}_index"], arrays[f"s{k}_threshold"], arrays[f"s{k}_sign"],
                            arrays[f"s{k}_weight"], float(b)) for k, b in enumerate(header["biases"])]
            _check_stages(stages, len(arrays["blocks"]) * 4 * BINS, tuple(header["calibration"]))
            model = cls(config, arrays["blocks"], stages, tuple(header["calibration"]))
        except (KeyError, TypeError, ValueError) as exc:
            raise ValueError(f"{path}: corrupt HOG cascade model ({exc})") from None
        expected = block_pool(config.window_px, config.cell_px)
        if not np.array_equal(expected, model.blocks):
            raise ValueError(f"{path}: block pool does not match window {config.window_px}")
        return model


def _check_stages(stages: list[Stage], n_features: int, calibration: tuple[float, ...]) -> None:
    """``ValueError`` naming the first stage whose arrays disagree in shape, index a feature outside
    ``0 .. n_features-1`` or hold a non-finite number (or a non-finite calibration)."""
    for k, s in enumerate(stages):
        n = len(s.index)
        if not (s.index.ndim == 1 and s.threshold.shape == s.sign.shape == s.weight.shape == (n,)):
            raise ValueError(f"stage {k}: index, threshold, sign and weight differ in shape")
        if n and (not np.issubdtype(s.index.dtype, np.integer) or s.index.min() < 0 or s.index.max() >= n_features):
            raise ValueError(f"stage {k}: feature indices must be integers in 0..{n_features - 1}")
        if not (np.isfinite(s.threshold).all() and np.isfinite(s.weight).all() and np.isfinite(s.bias)):
            raise ValueError(f"stage {k}: holds NaN or infinity")
    if len(calibration) != 2 or not np.isfinite(calibration).all():
        raise ValueError(f"calibration must be two finite numbers, got {calibration}")


def _margin(features: np.ndarray, stage: Stage) -> np.ndarray:
    """``(k,)`` vote sums of ``stage`` on the ``(k, n)`` columns its stumps read (in stump order)."""
    votes = np.where((features > stage.threshold) == (stage.sign > 0), 1.0, -1.0)
    return votes @ stage.weight  # type: ignore[no-any-return]


def train_cascade(
    positives: np.ndarray,
    negative_windows: Callable[[int, np.random.Generator], np.ndarray],
    config: CascadeConfig = CascadeConfig(),
    seed: int = 0,
    progress: Callable[[int, str], None] | None = None,
    scenes: Sequence[tuple[np.ndarray, np.ndarray]] = (),
) -> HogCascade:
    """Train a cascade.

    Args:
        positives: ``(n, h+2, w+2)`` grey positive windows with a 1-px margin (augmented already).
        negative_windows: ``(count, rng) -> (m, h+2, w+2)`` random background windows; only those the cascade so
            far accepts are kept.
        progress: called with ``(stage, message)`` after each stage.
        scenes: ``(grey (H, W) float32 frame, true boxes (m, 4) px)`` pairs: from the second stage on, windows the
            cascade accepts away from true boxes become negatives first."""
    with needs("sklearn"):
        from sklearn.ensemble import AdaBoostClassifier
        from sklearn.linear_model import LogisticRegression
        from sklearn.tree import DecisionTreeClassifier

    rng = np.random.default_rng(seed)
    blocks = block_pool(config.window_px, config.cell_px)
    pos = window_features(positives, blocks)
    model = HogCascade(config, blocks, [])
    neg = np.zeros((0, pos.shape[1]), np.float32)
    last_neg = neg
    for k in range(config.stages):
        # Refill the negatives with windows the cascade accepts, until the false-positive rate is below target.
        mined = 0
        if model.stages and scenes:
            found = _mine_scenes(model, scenes, config, config.negatives_per_stage - len(neg), rng)
            mined = len(found)
            neg = np.concatenate([neg, window_features(found, blocks)])
        drawn = accepted = 0
        for _ in range(config.max_draws_per_stage):
            if len(neg) >= config.negatives_per_stage:
                break
            cand = window_features(negative_windows(config.negatives_per_stage, rng), blocks)
            drawn += len(cand)
            if model.stages:
                cand = cand[model.classify(cand)[0]]
            accepted += len(cand)
            neg = np.concatenate([neg, cand])[: config.negatives_per_stage]
            if model.stages and drawn >= 5 * config.negatives_per_stage and \
                    accepted < config.target_false_positive_rate * drawn:
                break
        fp_rate = accepted / drawn if drawn else None
        if model.stages and mined < config.min_hard_negatives and fp_rate is not None \
                and fp_rate < config.target_false_positive_rate:
            if progress:
                progress(k, f"stopped: false-positive rate {fp_rate:.2e} below the target "
                            f"{config.target_false_positive_rate:.0e} ({accepted} of {drawn} windows)")
            break
        if len(neg) < config.min_hard_negatives:
            if progress:
                progress(k, f"stopped: only {len(neg)} hard negatives in {drawn} windows")
            break
        live = model.classify(pos)[0] if model.stages else np.ones(len(pos), bool)
        x = np.concatenate([pos[live], neg])
        y = np.concatenate([np.ones(int(live.sum())), -np.ones(len(neg))])
        n_stumps = min(config.max_stumps, 3 + 2 * k)
        boost = AdaBoostClassifier(DecisionTreeClassifier(max_depth=1), n_estimators=n_stumps,
                                   random_state=int(rng.integers(2**31 - 1)))
        boost.fit(x, y)
        stage = _stage_from_boost(boost)
        m_pos = stage.margin(pos[live])
        stage.bias = float(np.quantile(m_pos, 1.0 - config.stage_hit_rate)) - 1e-9
        model.stages.append(stage)
        model.__post_init__()
        rejected = float((stage.margin(neg) < stage.bias).mean())
        last_neg = neg
        neg = neg[stage.margin(neg) >= stage.bias]
        if progress:
            progress(k, f"{len(stage.index)} stumps, rejects {rejected:.1%} of {len(last_neg)} negatives "
                        f"({mined} mined from scenes)")
    # Probability: logistic fit of the last-stage margin, positives vs the last negatives.
    if model.stages and len(last_neg):
        last = model.stages[-1]
        m = np.concatenate([last.margin(pos), last.margin(last_neg)])
        yy = np.concatenate([np.ones(len(pos)), np.zeros(len(last_neg))])
        lr = LogisticRegression().fit(m[:, None], yy)
        model.calibration = (float(lr.coef_[0, 0]), float(lr.intercept_[0]))
    return model


def _mine_scenes(model: HogCascade, scenes: Sequence[tuple[np.ndarray, np.ndarray]], config: CascadeConfig,
                 count: int, rng: np.random.Generator) -> np.ndarray:
    """Up to ``count`` windows ``(k, h+2, w+2)`` that ``model`` accepts in ``scenes`` away from their true boxes,
    at most a tenth from any one scene."""
    from lookalike.vision.hog_features import crop_window

    per_scene = max(1, count // 10)
    out: list[np.ndarray] = []
    for k in rng.permutation(len(scenes)):
        if len(out) >= count:
            break
        grey, truth = scenes[k]
        xywh, _ = model.windows(np.asarray(grey, np.float32))
        if len(xywh) and len(truth):
            far = iou_matrix(model.target_boxes(xywh), np.asarray(truth, float)).max(axis=1)
            xywh = xywh[far <= config.hard_negative_max_iou]
        if len(xywh) > per_scene:
            xywh = xywh[rng.choice(len(xywh), per_scene, replace=False)]
        out.extend(crop_window(grey, box, config.window_px, pad=0.0) for box in xywh[: count - len(out)])
    h, w = config.window_px[1] + 2, config.window_px[0] + 2
    return np.array(out, np.float32).reshape(-1, h, w)


def _stage_from_boost(boost) -> Stage:
    index, threshold, sign, weight = [], [], [], []
    for est, w in zip(boost.estimators_, boost.estimator_weights_):
        tree = est.tree_
        if tree.node_count < 3 or w <= 0:
            continue
        left = tree.value[tree.children_left[0]][0]
        index.append(int(tree.feature[0]))
        threshold.append(float(tree.threshold[0]))
        # classes_ are (-1, +1); the right branch (> threshold) votes +1 when the left one is mostly negative.
        sign.append(1 if left[0] >= left[1] else -1)
        weight.append(float(w))
    return Stage(np.array(index, np.int64), np.array(threshold, np.float32), np.array(sign, np.int64),
                 np.array(weight), 0.0)
