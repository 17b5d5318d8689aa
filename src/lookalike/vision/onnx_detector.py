"""Any ONNX detection model as a box detector (``lookalike track --video V --detector FILE.onnx``): letterboxed float32
NCHW input (RGB unless ``rgb=False``, times ``scale``); output ``layout`` ``yolo`` (``(1, N, 4 + C)``, either axis
order), ``yolo-obj`` (with objectness) or ``ssd`` (boxes and scores), ``auto`` by the number of outputs; best class in
``classes``, ``score_threshold``, class-wise NMS at ``nms_iou``, boxes ``xywh`` in frame pixels."""

from __future__ import annotations

import os
from collections.abc import Callable, Iterable
from dataclasses import dataclass, fields
from pathlib import Path
from typing import Any

import numpy as np

from lookalike._optional import needs
from lookalike.types import Detections
from lookalike.types.mot_table import detection_rows
from lookalike.vision.nms import nms
from lookalike.vision.onnx_session import check_image_input, open_session

LAYOUTS = ("auto", "yolo", "yolo-obj", "ssd")


@dataclass(frozen=True)
class OnnxDetectorConfig:
    """How to read an ONNX detector (see the module docstring). Sizes in pixels."""

    layout: str = "auto"
    score_threshold: float = 0.25
    nms_iou: float = 0.45
    classes: tuple[int, ...] | None = None
    input_size: tuple[int, int] | None = None  # (width, height) for models without a static input shape
    rgb: bool = True
    scale: float = 1 / 255
    box_order: str = "xyxy"  # ssd only
    normalised: bool = True  # ssd only: boxes in [0, 1] of the input
    threads: int = 1

    def __post_init__(self) -> None:
        if self.layout not in LAYOUTS:
            raise ValueError(f"layout: choose one of {', '.join(LAYOUTS)}, got {self.layout!r}")
        if not 0 <= self.score_threshold <= 1 or not 0 < self.nms_iou <= 1:
            raise ValueError("score_threshold must be in [0, 1] and nms_iou in (0, 1]")
        if self.box_order not in ("xyxy", "yxyx"):
            raise ValueError(f"box_order: choose xyxy or yxyx, got {self.box_order!r}")
        if self.input_size is not None and min(self.input_size) < 8:
            raise ValueError(f"input_size: expected (width, height) of at least 8 px, got {self.input_size}")
        cpus = os.cpu_count() or 1
        if not 1 <= self.threads <= cpus:
            raise ValueError(f"threads: from 1 to this machine's {cpus} CPU(s), got {self.threads}")
        if self.classes is not None and min(self.classes) < 0:
            raise ValueError(f"classes: class indices are >= 0, got {','.join(map(str, self.classes))}")


def config_from_settings(settings: list[str]) -> OnnxDetectorConfig:
    """An :class:`OnnxDetectorConfig` from ``KEY=VALUE`` strings (``score=``, ``iou=``, ``classes=0,2``,
    ``input_size=640x480``); an unknown key or bad value raises ``ValueError`` naming it."""
    alias = {"score": "score_threshold", "iou": "nms_iou", "size": "input_size"}
    known = {f.name for f in fields(OnnxDetectorConfig)}
    values: dict[str, Any] = {}
    for text in settings:
        key, sep, raw = (part.strip() for part in text.partition("="))
        key = alias.get(key, key)
        if not sep or key not in known:
            raise ValueError(f"detector setting {text!r}: expected KEY=VALUE, KEY one of {', '.join(sorted(known))}")
        try:
            if key in ("score_threshold", "nms_iou", "scale"):
                values[key] = float(raw)
            elif key == "threads":
                values[key] = int(raw)
            elif key == "classes":
                values[key] = tuple(int(c) for c in raw.split(",") if c.strip()) or None
            elif key == "input_size":
                w, _, h = raw.lower().partition("x")
                values[key] = (int(w), int(h or w))
            elif key in ("rgb", "normalised"):
                if raw.lower() not in ("1", "0", "true", "false", "yes", "no"):
                    raise ValueError(raw)
                values[key] = raw.lower() in ("1", "true", "yes")
            else:
                values[key] = raw
        except ValueError:
            raise ValueError(f"detector setting {key}: bad value {raw!r}") from None
    return OnnxDetectorConfig(**values)


def letterbox(image: np.ndarray, size: tuple[int, int]) -> tuple[np.ndarray, float, tuple[float, float]]:
    """``image (h, w, 3)`` resized into ``size = (width, height)`` keeping its aspect, centred on grey 114, with the
    scale ``r`` and padding ``(dx, dy)``: a frame point ``p`` lands at ``r · p + (dx, dy)``."""
    with needs("cv2"):
        import cv2

    h, w = image.shape[:2]
    tw, th = size
    r = min(tw / w, th / h)
    nw, nh = max(1, round(w * r)), max(1, round(h * r))
    dx, dy = (tw - nw) // 2, (th - nh) // 2
    out = np.full((th, tw, 3), 114, dtype=np.uint8)
    out[dy : dy + nh, dx : dx + nw] = cv2.resize(image, (nw, nh), interpolation=cv2.INTER_LINEAR)
    return out, r, (float(dx), float(dy))


class OnnxDetector:
    """Runs an ONNX detection model on BGR frames; ``detector(image)`` gives :class:`Detections`
    (boxes ``xywh`` in frame pixels, ``score``, ``label`` = class index)."""

    def __init__(self, path: Path | str, config: OnnxDetectorConfig | None = None) -> None:
        self.path = Path(path)
        self.config = config or OnnxDetectorConfig()
        self.session = open_session(self.path, self.config.threads, "ONNX model")
        inp = self.session.get_inputs()
        if len(inp) != 1 or len(inp[0].shape) != 4:
            raise ValueError(f"{self.path}: expected one NCHW image input, got {[i.shape for i in inp]}")
        self.input_name = inp[0].name
        check_image_input(self.path, inp[0], "image", "RGB, or BGR with rgb=0, pixels times scale=...")
        h, w = inp[0].shape[2:]
        if isinstance(h, int) and isinstance(w, int):
            self.input_size = (w, h)
        else:
            self.input_size = self.config.input_size or (640, 640)
        n_out = len(self.session.get_outputs())
        layout = self.config.layout
        if layout == "auto":
            layout = "yolo" if n_out == 1 else "ssd"
        if (layout == "ssd") != (n_out == 2) or n_out > 2:
            raise ValueError(f"{self.path}: layout {layout!r} does not fit a model with {n_out} output(s)")
        self.layout = layout

    def __call__(self, image: np.ndarray) -> Detections:
        """Detections of one BGR uint8 frame ``(h, w, 3)``."""
        img = np.asarray(image)
        if img.ndim != 3 or img.shape[2] != 3 or img.dtype != np.uint8:
            raise ValueError(f"image: expected (h, w, 3) uint8, got {img.shape} {img.dtype}")
        boxed, r, (dx, dy) = letterbox(img, self.input_size)
        if self.config.rgb:
            boxed = boxed[..., ::-1]
        tensor = np.ascontiguousarray(boxed.transpose(2, 0, 1)[None], dtype=np.float32) * np.float32(self.config.scale)
        outputs = self.session.run(None, {self.input_name: tensor})
        xyxy, scores = self._decode([np.asarray(o, dtype=float) for o in outputs])
        return self._select(xyxy, scores, r, dx, dy, img.shape[1], img.shape[0])

    def _decode(self, outputs: list[np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
        """Boxes ``(N, 4)`` x0, y0, x1, y1 in input pixels and class scores ``(N, C)``."""
        if self.layout == "ssd":
            boxes, scores = (outputs if outputs[0].shape[-1] == 4 else outputs[::-1])
            n = boxes.size // 4 if boxes.shape[-1] == 4 else -1
            if n < 0 or (scores.size % n if n else scores.size):
                raise ValueError(f"{self.path}: SSD outputs {outputs[0].shape} and {outputs[1].shape} do not match: "
                                 "expected boxes (..., N, 4) and scores with N rows")
            boxes = boxes.reshape(-1, 4)
            scores = scores.reshape(len(boxes), -1)
            if self.config.box_order == "yxyx":
                boxes = boxes[:, [1, 0, 3, 2]]
            if self.config.normalised:
                boxes = boxes * np.tile(self.input_size, 2)
            return boxes, scores
        out = outputs[0]
        out = out.reshape(out.shape[-2:]) if out.ndim == 3 else out
        if out.ndim != 2:
            raise ValueError(f"{self.path}: a YOLO-style output must be (1, N, K) or (N, K), got {outputs[0].shape}")
        if out.shape[0] < out.shape[1]:
            out = out.T  # (4 + C, N) -> (N, 4 + C)
        first = 5 if self.layout == "yolo-obj" else 4
        if out.shape[1] <= first:
            raise ValueError(f"{self.path}: {out.shape[1]} values per box leave no class score ({self.layout})")
        scores = out[:, first:] * (out[:, 4:5] if self.layout == "yolo-obj" else 1.0)
        c, half = out[:, :2], out[:, 2:4] / 2
        return np.hstack([c - half, c + half]), scores

    def _select(self, xyxy: np.ndarray, scores: np.ndarray, r: float, dx: float, dy: float,
                width: int, height: int) -> Detections:
        classes = self.config.classes
        if classes is not None:
            if max(classes) >= scores.shape[1]:
                raise ValueError(f"classes: the model gives {scores.shape[1]} class score(s), asked for {classes}")
            cols = np.array(classes)
        else:
            cols = np.arange(scores.shape[1])
        best = scores[:, cols].argmax(axis=1)
        label = cols[best]
        score = scores[np.arange(len(scores)), label]
        keep = score >= self.config.score_threshold
        xyxy, score, label = xyxy[keep], score[keep], label[keep]
        xyxy = (xyxy - np.array([dx, dy, dx, dy])) / r
        xyxy[:, [0, 2]] = np.clip(xyxy[:, [0, 2]], 0, width)
        xyxy[:, [1, 3]] = np.clip(xyxy[:, [1, 3]], 0, height)
        xywh = np.column_stack([xyxy[:, :2], xyxy[:, 2:] - xyxy[:, :2]])
        ok = (xywh[:, 2] > 1) & (xywh[:, 3] > 1)
        xywh, score, label = xywh[ok], score[ok], label[ok]
        kept = [idx[nms(xywh[idx], score[idx], self.config.nms_iou)] for lab in np.unique(label)
                for idx in [np.flatnonzero(label == lab)]]
        order = np.concatenate(kept) if kept else np.zeros(0, dtype=int)
        order = order[np.argsort(-score[order], kind="stable")]
        return Detections(xywh=xywh[order], score=score[order], label=label[order].astype(int))


def detect_frames(frames: Iterable[np.ndarray], detector: Callable[[np.ndarray], Detections],
                  advance: Callable[[], None] | None = None) -> tuple[np.ndarray, int]:
    """MOTChallenge detection rows ``(n, 10)`` (1-based frames, id -1, box px, score) and the number of frames."""
    chunks = []
    count = 0
    for k, image in enumerate(frames):
        det = detector(image)
        if len(det):
            assert det.xywh is not None and det.score is not None
            chunks.append(detection_rows(k + 1, det.xywh, det.score))
        count = k + 1
        if advance is not None:
            advance()
    return (np.vstack(chunks) if chunks else np.zeros((0, 10))), count


__all__ = ["LAYOUTS", "OnnxDetector", "OnnxDetectorConfig", "config_from_settings", "detect_frames", "letterbox"]
