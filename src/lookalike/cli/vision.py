"""``lookalike train-detector`` and ``lookalike train-heading``: train the vision models of DESIGN §6.

Both train from rendered robots (:mod:`lookalike.sim.render_robots`) by default; the detector also
trains from a folder with ``positives/`` (images each showing one target filling the window, any
size) and ``negatives/`` (images without targets, from which windows are sampled). A detector trained on
rendered robots is then cut to the cascade prefix (and pyramid start) with the best F1 on held-out
renders, whose detections also calibrate its probability (:mod:`lookalike.vision.hog_select`).
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any, Optional

import numpy as np
import typer
from rich.progress import (
    BarColumn,
    MofNCompleteColumn,
    Progress,
    TextColumn,
    TimeElapsedColumn,
)

from lookalike.cli.app import app, console, fail

IMAGE_SUFFIXES = (".png", ".jpg", ".jpeg", ".bmp", ".tif", ".tiff")


def _progress() -> Progress:
    return Progress(TextColumn("{task.description}"), BarColumn(), MofNCompleteColumn(), TimeElapsedColumn(),
                    TextColumn("{task.fields[note]}"), console=console)


def rendered_detector_data(
    n_frames: int, seed: int, window_px: tuple[int, int], min_visible: float = 0.7,
    height_px: tuple[float, float] = (40.0, 400.0), camera: object | None = None,
    step: Callable[[], None] | None = None,
) -> tuple[np.ndarray, list[np.ndarray], list[np.ndarray]]:
    """Grey positive windows ``(n, h+2, w+2)`` of rendered robots (1-5 m, random headings, 1-4 per frame), the
    grey frames and their ground-truth boxes ``(m, 4)`` (px) for sampling negatives. Deterministic by ``seed``."""
    from lookalike.vision.hog_features import crop_window, to_grey

    pos, frames, truths = [], [], []
    for frame in _rendered_frames(n_frames, seed, camera):
        grey = to_grey(frame.image)
        frames.append(grey)
        truths.append(frame.xywh)
        ok = (frame.visible >= min_visible) & (frame.xywh[:, 3] >= height_px[0]) & (frame.xywh[:, 3] <= height_px[1])
        pos.extend(crop_window(grey, box, window_px) for box in frame.xywh[ok])
        if step:
            step()
    h, w = window_px[1] + 2, window_px[0] + 2
    return np.array(pos, np.float32).reshape(-1, h, w), frames, truths


def _rendered_frames(n_frames: int, seed: int, camera: object | None = None) -> Iterator[Any]:
    """Rendered frames of 1-4 robots 1-5 m ahead (depth), across a little more than the field of view,
    random headings. Deterministic by ``seed``."""
    from lookalike.geometry.camera import Camera
    from lookalike.sim.render_robots import RobotRenderer

    cam = camera if camera is not None else Camera.default()
    renderer = RobotRenderer(camera=cam, seed=seed)
    rng = np.random.default_rng(seed)
    half_fov = np.arctan(0.5 * cam.intrinsics.width / cam.intrinsics.fx)
    for _ in range(n_frames):
        n = int(rng.integers(1, 5))
        depth = rng.uniform(1.0, 5.0, n)
        lateral = depth * np.tan(rng.uniform(-1.1 * half_fov, 1.1 * half_fov, n))
        yield renderer.render(np.column_stack([depth, lateral]), rng.uniform(-np.pi, np.pi, n))


def rendered_held_out_scenes(n_frames: int, seed: int, camera: object | None = None) -> list[Any]:
    """Rendered frames as :class:`~lookalike.vision.hog_select.HeldOutScene`: robots at least half visible are
    targets, the others in view are ignored."""
    from lookalike.vision.hog_select import HeldOutScene

    return [HeldOutScene(f.image, f.xywh[f.visible >= 0.5], f.xywh[(f.visible < 0.5) & (f.visible > 0)])
            for f in _rendered_frames(n_frames, seed, camera)]


def negative_sampler(frames: list[np.ndarray], truths: list[np.ndarray], window_px: tuple[int, int],
                     height_px: tuple[float, float], max_iou: float = 0.2
                     ) -> Callable[[int, np.random.Generator], np.ndarray]:
    """``(count, rng) -> (count, h+2, w+2)`` random windows of ``frames`` (heights log-uniform in ``height_px``)
    that overlap no box of ``truths`` by more than ``max_iou``."""
    from lookalike.geometry.boxes import iou_matrix
    from lookalike.vision.hog_features import crop_window

    aspect = window_px[0] / window_px[1]

    def sample(count: int, rng: np.random.Generator) -> np.ndarray:
        out = []
        while len(out) < count:
            k = int(rng.integers(len(frames)))
            img, gt = frames[k], truths[k]
            hh = float(np.exp(rng.uniform(*np.log(height_px))))
            hh = min(hh, img.shape[0] - 1.0)
            ww = hh * aspect
            box = np.array([[rng.uniform(0, max(1.0, img.shape[1] - ww)), rng.uniform(0, img.shape[0] - hh), ww, hh]])
            if len(gt) and iou_matrix(box, gt).max() > max_iou:
                continue
            out.append(crop_window(img, box[0], window_px, pad=0.0))
        return np.array(out, np.float32)

    return sample


def _read_grey(path: Path) -> np.ndarray:
    import cv2

    from lookalike.vision.hog_features import as_bgr_image, to_grey

    img = cv2.imread(str(path), cv2.IMREAD_UNCHANGED)
    if img is None:
        raise ValueError(f"{path}: not a readable image")
    return to_grey(as_bgr_image(img, str(path)))


def folder_detector_data(folder: Path, window_px: tuple[int, int]) -> tuple[np.ndarray, list[np.ndarray]]:
    """Positive windows from ``folder/positives`` (each image resized to the window) and negative images from
    ``folder/negatives``."""
    import cv2

    def images(sub: str) -> list[Path]:
        d = folder / sub
        if not d.is_dir():
            raise ValueError(f"{folder}: needs a '{sub}' subfolder of images")
        files = sorted(p for p in d.iterdir() if p.suffix.lower() in IMAGE_SUFFIXES)
        if not files:
            raise ValueError(f"{d}: no images ({', '.join(IMAGE_SUFFIXES)})")
        return files

    size = (window_px[0] + 2, window_px[1] + 2)
    pos = np.array([cv2.resize(_read_grey(p), size, interpolation=cv2.INTER_AREA) for p in images("positives")])
    negs = [_read_grey(p) for p in images("negatives")]
    return pos.astype(np.float32), negs


@app.command("train-detector")
def train_detector(
    output: Path = typer.Option(..., "-o", "--output", help="Model file to write (.npz)."),
    data: Optional[Path] = typer.Option(None, help="Folder with positives/ and negatives/ images; default: rendered robots."),
    frames: int = typer.Option(300, help="Rendered frames to train on (without --data)."),
    stages: int = typer.Option(20, help="Cascade stages."),
    negatives: int = typer.Option(2000, help="Hard negatives per stage."),
    copies: int = typer.Option(2, help="Augmented copies per positive (rotation ±15°, scale, flip, cut-outs)."),
    seed: int = typer.Option(0, help="Seed of rendering, augmentation and boosting."),
    validation_frames: int = typer.Option(100, help="Held-out rendered frames (seed + 1000003) that choose the "
                                          "cascade prefix and pyramid start and calibrate the probability "
                                          "(without --data; 0: keep every stage)."),
) -> None:
    """Train the HOG cascade robot detector and save it."""
    from lookalike.vision.hog_cascade import CascadeConfig, train_cascade
    from lookalike.vision.hog_features import augment_windows
    from lookalike.vision.hog_select import select_stages

    try:
        # Folder positives fill their whole window; rendered ones carry the default context margin.
        pad = {"context_pad": 0.0} if data is not None else {}
        config = CascadeConfig(stages=stages, negatives_per_stage=negatives, **pad)
        if frames < 1 or copies < 0 or validation_frames < 0:
            raise ValueError(f"--frames/--copies/--validation-frames: need frames >= 1, copies >= 0 and "
                             f"validation_frames >= 0, got {frames}, {copies}, {validation_frames}")
        heights = (config.min_height_px, config.max_height_px)
        with _progress() as bar:
            if data is not None:
                pos, neg_images = folder_detector_data(data, config.window_px)
                truths = [np.zeros((0, 4)) for _ in neg_images]
            else:
                task = bar.add_task("rendering", total=frames, note="")
                pos, neg_images, truths = rendered_detector_data(
                    frames, seed, config.window_px, height_px=heights, step=lambda: bar.advance(task))
            if len(pos) < 10:
                raise ValueError(f"only {len(pos)} positive windows; need at least 10")
            rng = np.random.default_rng(seed)
            if copies:
                extra = augment_windows(pos[:, 1:-1, 1:-1], copies, rng)
                pos = np.concatenate([pos, np.pad(extra, ((0, 0), (1, 1), (1, 1)), mode="edge")])
            sampler = negative_sampler(neg_images, truths, config.window_px, heights)
            task = bar.add_task(f"training on {len(pos)} positives", total=stages, note="")

            def on_stage(k: int, message: str) -> None:
                bar.update(task, completed=k + 1, note=message)

            # Hard negatives are also mined from whole frames (windows the cascade accepts away from robots).
            model = train_cascade(pos, sampler, config, seed=seed, progress=on_stage,
                                  scenes=list(zip(neg_images, truths)))
            trained, tried = len(model.stages), []
            if data is None and validation_frames:
                task = bar.add_task("held-out selection", total=1, note="")
                model, tried = select_stages(model, rendered_held_out_scenes(validation_frames, seed + 1000003))
                bar.update(task, completed=1)
    except ValueError as exc:
        fail(str(exc))
    model.save(output)
    if tried:
        best = next(t for t in tried if t.stages == len(model.stages)
                    and t.min_height_px == model.config.min_height_px)
        console.print(f"held-out ({validation_frames} frames): kept {len(model.stages)} of {trained} stages, pyramid "
                      f"from {model.config.min_height_px:g} px; precision {best.precision:.3f}, recall "
                      f"{best.recall:.3f}")
    console.print(f"wrote {output}: {len(model.stages)} stages, {sum(len(s.index) for s in model.stages)} stumps")


@app.command("train-heading")
def train_heading_command(
    output: Path = typer.Option(..., "-o", "--output", help="Model file to write (.npz)."),
    frames: int = typer.Option(400, help="Rendered training frames (4 robots each)."),
    test_frames: int = typer.Option(100, help="Rendered held-out frames for the reported error (0: none)."),
    folds: int = typer.Option(3, help="Folds of the grid search."),
    seed: int = typer.Option(0, help="Seed of the training renders; held-out renders use seed + 1000003."),
) -> None:
    """Train the heading classifier on rendered robots, report its held-out error and save it."""
    from lookalike.vision.heading import (
        HeadingConfig,
        mean_abs_error_deg,
        rendered_heading_samples,
        train_heading,
    )

    try:
        config = HeadingConfig(folds=folds)
        if frames < 1 or test_frames < 0:
            raise ValueError(f"--frames/--test-frames: need frames >= 1, test_frames >= 0, got {frames}, {test_frames}")
        with _progress() as bar:
            task = bar.add_task("rendering", total=frames + test_frames, note="")
            parts = []
            for start in range(0, frames, 20):  # in chunks, for the progress bar; each chunk its own seed
                n = min(20, frames - start)
                parts.append(rendered_heading_samples(n, seed * 7919 + start, config))
                bar.advance(task, n)
            f = np.concatenate([p[0] for p in parts])
            h = np.concatenate([p[1] for p in parts])
            ft, ht = (rendered_heading_samples(test_frames, seed + 1000003, config) if test_frames
                      else (np.zeros((0, f.shape[1])), np.zeros(0)))
            bar.advance(task, test_frames)
            fit = bar.add_task(f"grid search on {len(f)} robots", total=1, note="")
            model = train_heading(f, h, config, seed=seed, progress=lambda m: bar.update(fit, note=m))
            bar.update(fit, completed=1)
    except ValueError as exc:
        fail(str(exc))
    model.save(output)
    if len(ft):
        err = mean_abs_error_deg(model.estimate(ft).heading_rad, ht)
        console.print(f"held-out mean absolute heading error: {err:.1f} deg on {len(ft)} robots")
    console.print(f"wrote {output} (C={model.c:g}, {len(model.support)} support vectors)")
