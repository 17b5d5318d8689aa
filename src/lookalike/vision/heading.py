"""Visual heading classifier: dense HOG (grey and hue) of a box's upper half and its centre into an RBF SVM over
``classes`` heading sectors, evaluated in numpy (pairwise coupling of Platt probabilities): a class, a continuous
egocentric heading (rad) and its spread per box."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np

from lookalike._optional import needs
from lookalike.vision.hog_features import as_bgr_image, dense_hog, hue_channel, to_grey
from lookalike.vision.model_file import load_model_file, save_model_file

FORMAT = "lookalike-heading-svm"
VERSION = 1


@dataclass(frozen=True)
class HeadingConfig:
    """Feature and training settings: ``patch_px`` (width, height) of the torso crop; ``gamma_grid`` in units of
    ``1 / n_features``."""

    classes: int = 10
    patch_px: tuple[int, int] = (32, 32)
    cell_px: int = 8
    centre_weight: float = 4.0  # scale of the standardised box-centre features relative to one HOG value
    folds: int = 3
    c_grid: tuple[float, ...] = (1.0, 10.0, 100.0)
    gamma_grid: tuple[float, ...] = (0.5, 1.0, 2.0)

    def __post_init__(self) -> None:
        if self.classes < 2:
            raise ValueError(f"HeadingConfig.classes: need >= 2, got {self.classes}")
        w, h = self.patch_px
        if self.cell_px < 2 or w < 2 * self.cell_px or h < 2 * self.cell_px:
            raise ValueError(f"HeadingConfig.patch_px: {self.patch_px} must hold >= 2x2 cells of {self.cell_px} px")
        if self.folds < 2:
            raise ValueError(f"HeadingConfig.folds: need >= 2, got {self.folds}")
        if not self.c_grid or not self.gamma_grid or min(self.c_grid) <= 0 or min(self.gamma_grid) <= 0:
            raise ValueError("HeadingConfig.c_grid/gamma_grid: need non-empty grids of positive values")
        if self.centre_weight < 0:
            raise ValueError(f"HeadingConfig.centre_weight: must be >= 0, got {self.centre_weight}")

    @property
    def sector_rad(self) -> float:
        return 2.0 * np.pi / self.classes


def heading_class(heading_rad: np.ndarray, classes: int = 10) -> np.ndarray:
    """Class index ``(n,)`` of headings (rad): sector ``k`` is centred on ``k * 2π / classes``."""
    h = np.asarray(heading_rad, dtype=float)
    return np.mod(np.round(h / (2.0 * np.pi / classes)), classes).astype(np.int64)


def class_centres(classes: int = 10) -> np.ndarray:
    """``(classes,)`` sector centres in (-π, π] (rad)."""
    c = np.arange(classes) * (2.0 * np.pi / classes)
    return np.where(c > np.pi, c - 2.0 * np.pi, c)


def heading_features(image: np.ndarray, xywh: np.ndarray, config: HeadingConfig = HeadingConfig()) -> np.ndarray:
    """Features ``(n, d)`` float32 of boxes ``xywh (n, 4)`` (px) in ``image``: grey HOG, hue HOG, relative centre."""
    with needs("cv2"):
        import cv2

    img = as_bgr_image(image)
    boxes = np.asarray(xywh, dtype=float)
    if boxes.size == 0:
        boxes = boxes.reshape(0, 4)
    if boxes.ndim != 2 or boxes.shape[1] != 4:
        raise ValueError(f"xywh: expected shape (n, 4), got {boxes.shape}")
    if not np.isfinite(boxes).all() or (boxes[:, 2:] <= 0).any():
        raise ValueError("xywh: boxes must be finite with positive width and height")
    pw, ph = config.patch_px
    height, width = img.shape[:2]
    out = []
    for x, y, w, h in boxes:
        # Affine map from the patch to the upper half of the box (border pixels replicated).
        m = np.array([[w / pw, 0, x], [0, 0.5 * h / ph, y]], dtype=np.float32)
        patch = cv2.warpAffine(img, m, (pw, ph), flags=cv2.INTER_AREA | cv2.WARP_INVERSE_MAP,
                               borderMode=cv2.BORDER_REPLICATE)
        centre = ((x + w / 2) / width, (y + h / 2) / height)
        out.append(np.concatenate([dense_hog(to_grey(patch), config.cell_px),
                                   dense_hog(hue_channel(patch), config.cell_px), centre]))
    d = feature_length(config)
    return np.array(out, dtype=np.float32).reshape(-1, d)


def feature_length(config: HeadingConfig) -> int:
    """Length of a row of :func:`heading_features`: two dense HOG blocks (grey, hue) and the box centre."""
    nx, ny = config.patch_px[0] // config.cell_px, config.patch_px[1] // config.cell_px
    return 2 * (nx - 1) * (ny - 1) * 4 * 9 + 2


@dataclass(frozen=True)
class HeadingEstimate:
    """Per-box output: ``label (n,)`` class index, ``heading_rad (n,)`` continuous estimate in (-π, π],
    ``heading_std_rad (n,)`` spread, ``prob (n, classes)`` class probabilities."""

    label: np.ndarray
    heading_rad: np.ndarray
    heading_std_rad: np.ndarray
    prob: np.ndarray


@dataclass
class HeadingClassifier:
    """A fitted classifier: feature scaling, support vectors and Platt/coupling parameters (numpy only)."""

    config: HeadingConfig
    mean: np.ndarray  # (d,) feature mean
    scale: np.ndarray  # (d,) feature scale (centre columns include centre_weight)
    classes: np.ndarray  # (k,) class indices present in training
    support: np.ndarray  # (s, d) standardised support vectors, grouped by class
    n_support: np.ndarray  # (k,) support vectors per class
    dual_coef: np.ndarray  # (k-1, s) libsvm one-vs-one layout
    intercept: np.ndarray  # (k(k-1)/2,)
    prob_a: np.ndarray  # (k(k-1)/2,) Platt slope per pair
    prob_b: np.ndarray  # (k(k-1)/2,) Platt offset per pair
    gamma: float
    c: float

    def _standardise(self, features: np.ndarray) -> np.ndarray:
        f = np.asarray(features, dtype=np.float64)
        if f.ndim != 2 or f.shape[1] != len(self.mean):
            raise ValueError(f"features: expected shape (n, {len(self.mean)}), got {f.shape}")
        return (f - self.mean) / self.scale

    def decision_values(self, features: np.ndarray) -> np.ndarray:
        """One-vs-one decision values ``(n, k(k-1)/2)``, pairs ordered (0,1), (0,2), ..., (k-2,k-1)."""
        x = self._standardise(features)
        sq = (x * x).sum(1)[:, None] + (self.support**2).sum(1)[None, :] - 2.0 * x @ self.support.T
        kern = np.exp(-self.gamma * np.maximum(sq, 0.0))
        start = np.concatenate([[0], np.cumsum(self.n_support)])
        k = len(self.classes)
        out = np.empty((len(x), k * (k - 1) // 2))
        p = 0
        for i in range(k):
            si = slice(start[i], start[i + 1])
            for j in range(i + 1, k):
                sj = slice(start[j], start[j + 1])
                out[:, p] = (kern[:, si] @ self.dual_coef[j - 1, si] + kern[:, sj] @ self.dual_coef[i, sj]
                             + self.intercept[p])
                p += 1
        return out

    def predict_proba(self, features: np.ndarray) -> np.ndarray:
        """Class probabilities ``(n, classes)`` (zero for classes unseen in training)."""
        k = len(self.classes)
        out = np.zeros((len(np.atleast_2d(features)), self.config.classes))
        if k == 1:
            out[:, self.classes[0]] = 1.0
            return out
        dec = self.decision_values(features)
        r = np.clip(1.0 / (1.0 + np.exp(dec * self.prob_a + self.prob_b)), 1e-7, 1 - 1e-7)
        pair = np.zeros((len(dec), k, k))  # pair[n, i, j] = P(class i | i or j)
        iu = np.triu_indices(k, 1)
        pair[:, iu[0], iu[1]] = r
        pair[:, iu[1], iu[0]] = 1.0 - r
        # Pairwise coupling: minimise p' Q p with sum(p) = 1, solved as one linear system per row.
        q = -pair.transpose(0, 2, 1) * pair
        diag = (pair.transpose(0, 2, 1) ** 2).sum(axis=2) - (np.diagonal(pair, axis1=1, axis2=2) ** 2)
        q[:, np.arange(k), np.arange(k)] = diag
        a = np.zeros((len(dec), k + 1, k + 1))
        a[:, :k, :k] = q
        a[:, :k, k] = a[:, k, :k] = 1.0
        rhs = np.zeros((len(dec), k + 1))
        rhs[:, k] = 1.0
        p = np.clip(np.linalg.solve(a, rhs[..., None])[..., 0][:, :k], 0.0, None)
        out[:, self.classes] = p / p.sum(axis=1, keepdims=True)
        return out

    def estimate(self, features: np.ndarray) -> HeadingEstimate:
        """Class, continuous heading and spread (rad) from features ``(n, d)``."""
        prob = self.predict_proba(features)
        centres = class_centres(self.config.classes)
        z = prob @ np.exp(1j * centres)
        resultant = np.clip(np.abs(z), 1e-12, 1.0)
        circ_var = -2.0 * np.log(resultant)  # circular variance of the class distribution (rad^2)
        sector_var = self.config.sector_rad**2 / 12.0  # uniform spread inside one sector
        heading = np.angle(z)
        heading = np.where(heading <= -np.pi, heading + 2 * np.pi, heading)
        return HeadingEstimate(np.argmax(prob, axis=1), heading, np.sqrt(circ_var + sector_var), prob)

    def __call__(self, image: np.ndarray, xywh: np.ndarray) -> HeadingEstimate:
        """Estimate the heading (egocentric, rad) of each box ``xywh (n, 4)`` (px) in ``image``."""
        return self.estimate(heading_features(image, xywh, self.config))

    def save(self, path: str | Path) -> Path:
        """Write the model to ``path`` (``.npz``, no pickle) with its format name and version."""
        header = {"config": asdict(self.config), "gamma": self.gamma, "c": self.c, "features": len(self.mean)}
        arrays = {name: getattr(self, name) for name in _ARRAYS}
        arrays["support"] = arrays["support"].astype(np.float32)  # half the size; read back as float64
        return save_model_file(path, FORMAT, VERSION, header, arrays)

    @classmethod
    def load(cls, path: str | Path) -> HeadingClassifier:
        """Read a model written by :meth:`save`; a foreign, corrupt or other-version file raises ``ValueError``."""
        header, arrays = load_model_file(path, FORMAT, VERSION, "heading model")
        try:
            cfg = header["config"]
            config = HeadingConfig(**{**cfg, "patch_px": tuple(cfg["patch_px"]), "c_grid": tuple(cfg["c_grid"]),
                                      "gamma_grid": tuple(cfg["gamma_grid"])})
            arrays["support"] = np.asarray(arrays["support"], dtype=np.float64)
            model = cls(config, **{n: arrays[n] for n in _ARRAYS}, gamma=float(header["gamma"]), c=float(header["c"]))
            _check_shapes(model, int(header["features"]))
        except (KeyError, TypeError, ValueError) as exc:
            raise ValueError(f"{path}: corrupt heading model ({exc})") from None
        return model


_ARRAYS = ("mean", "scale", "classes", "support", "n_support", "dual_coef", "intercept", "prob_a", "prob_b")


def _check_shapes(m: HeadingClassifier, d: int) -> None:
    k, s = len(m.classes), int(m.n_support.sum())
    pairs = k * (k - 1) // 2
    if d != feature_length(m.config) or m.mean.shape != (d,) or m.scale.shape != (d,):
        raise ValueError(f"feature size {d} does not match the configuration")
    if m.support.shape != (s, d) or m.dual_coef.shape != (max(k - 1, 0), s) or len(m.n_support) != k:
        raise ValueError("support vector arrays disagree")
    if not (m.intercept.shape == m.prob_a.shape == m.prob_b.shape == (pairs,)):
        raise ValueError("pairwise arrays disagree with the number of classes")
    if k and (m.classes.min() < 0 or m.classes.max() >= m.config.classes):
        raise ValueError("class indices out of range")
    if not all(np.isfinite(a).all() for a in (m.mean, m.scale, m.support, m.dual_coef, m.intercept, m.prob_a, m.prob_b,
                                               m.gamma)):
        raise ValueError("holds NaN or infinity")


def train_heading(
    features: np.ndarray,
    heading_rad: np.ndarray,
    config: HeadingConfig = HeadingConfig(),
    seed: int = 0,
    progress: Callable[[str], None] | None = None,
) -> HeadingClassifier:
    """Fit on ``features (n, d)`` of :func:`heading_features` and true headings ``(n,)`` (rad); C and γ by a
    ``config.folds``-fold grid search on the mean angular error."""
    with needs("sklearn"):
        from sklearn.metrics import make_scorer
        from sklearn.model_selection import GridSearchCV, KFold
        from sklearn.svm import SVC

    f = np.asarray(features, dtype=np.float64)
    h = np.asarray(heading_rad, dtype=float).reshape(-1)
    d = feature_length(config)
    if f.ndim != 2 or f.shape[1] != d:
        raise ValueError(f"features: expected shape (n, {d}) for this configuration, got {f.shape}")
    if len(h) != len(f) or not np.isfinite(h).all() or not np.isfinite(f).all():
        raise ValueError("heading_rad: need one finite heading per feature row (and finite features)")
    y = heading_class(h, config.classes)
    if len(np.unique(y)) < 2 or len(f) < 2 * config.folds:
        raise ValueError(f"heading_rad: need >= {2 * config.folds} samples over >= 2 classes, got {len(f)}")
    mean = f.mean(axis=0)
    scale = f.std(axis=0)
    scale[scale < 1e-6] = 1.0
    if config.centre_weight > 0:
        scale[-2:] /= config.centre_weight
    else:
        scale[-2:] = np.inf
    x = (f - mean) / scale
    centres = class_centres(config.classes)

    def neg_error(y_true: np.ndarray, y_pred: np.ndarray) -> float:
        diff = np.angle(np.exp(1j * (centres[y_true] - centres[y_pred])))
        return -float(np.abs(diff).mean())

    grid = {"C": list(config.c_grid), "gamma": [g / d for g in config.gamma_grid]}
    search = GridSearchCV(SVC(kernel="rbf"), grid, scoring=make_scorer(neg_error),
                          cv=KFold(config.folds, shuffle=True, random_state=seed), n_jobs=1)
    search.fit(x, y)
    best = search.best_params_
    if progress:
        progress(f"grid search: C={best['C']:g}, gamma={best['gamma'] * d:g}/d, "
                 f"cv error {np.degrees(-search.best_score_):.1f} deg")
    svc = SVC(kernel="rbf", C=best["C"], gamma=best["gamma"], decision_function_shape="ovo").fit(x, y)
    prob_a, prob_b = _platt_pairs(svc, x, y, config.folds, seed)
    k = len(svc.classes_)
    return HeadingClassifier(
        config=config, mean=mean, scale=scale, classes=svc.classes_.astype(np.int64),
        support=svc.support_vectors_.astype(np.float64), n_support=svc.n_support_.astype(np.int64),
        dual_coef=svc.dual_coef_.astype(np.float64).reshape(k - 1, -1),
        intercept=svc.intercept_.astype(np.float64), prob_a=prob_a, prob_b=prob_b,
        gamma=float(best["gamma"]), c=float(best["C"]),
    )


def _platt_pairs(svc, x: np.ndarray, y: np.ndarray, folds: int, seed: int) -> tuple[np.ndarray, np.ndarray]:
    """Platt sigmoid ``P(i | i or j) = 1 / (1 + exp(A f + B))`` per class pair, on out-of-fold decision values."""
    with needs("sklearn"):
        from sklearn.base import clone
        from sklearn.linear_model import LogisticRegression
        from sklearn.model_selection import KFold, cross_val_predict

    cv = KFold(folds, shuffle=True, random_state=seed + 1)
    try:
        dec = cross_val_predict(clone(svc), x, y, cv=cv, method="decision_function")
    except ValueError:  # a class too rare to be in every training fold: in-sample values (overconfident)
        dec = svc.decision_function(x)
    if dec.reshape(len(x), -1).shape[1] != len(svc.classes_) * (len(svc.classes_) - 1) // 2:
        dec = svc.decision_function(x)
    classes = svc.classes_
    k = len(classes)
    dec = dec.reshape(len(x), -1)
    a, b = np.zeros(k * (k - 1) // 2), np.zeros(k * (k - 1) // 2)
    p = 0
    for i in range(k):
        for j in range(i + 1, k):
            rows = (y == classes[i]) | (y == classes[j])
            target = (y[rows] == classes[i]).astype(int)
            if 0 < target.sum() < len(target):
                lr = LogisticRegression(C=1e4).fit(dec[rows, p : p + 1], target)
                a[p], b[p] = -float(lr.coef_[0, 0]), -float(lr.intercept_[0])
            else:  # cannot happen for classes seen in training; kept as a safe default
                a[p], b[p] = -2.0, 0.0
            p += 1
    return a, b


def mean_abs_error_deg(estimate_rad: np.ndarray, truth_rad: np.ndarray) -> float:
    """Mean absolute angular difference in degrees."""
    diff = np.angle(np.exp(1j * (np.asarray(estimate_rad, float) - np.asarray(truth_rad, float))))
    return float(np.degrees(np.abs(diff)).mean())
