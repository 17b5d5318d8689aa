"""Learned appearance features: an ONNX embedding network (onnxruntime) of float32 NCHW BGR crops in [0, 1], returning
L2-normalised ``(n, d)`` embeddings. The shipped :data:`LEARNED_MODEL` embeds divers in 32 dimensions from 64×32 px."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from lookalike.vision.appearance import crop_boxes
from lookalike.vision.onnx_session import check_image_input, open_session

LEARNED_MODEL = Path(__file__).parent / "models_data" / "diver_reid.onnx"


class OnnxAppearance:
    """An ONNX embedding network as a :class:`~lookalike.vision.appearance.FeatureExtractor`."""

    def __init__(self, path: Path | str = LEARNED_MODEL, threads: int = 1, batch: int = 64) -> None:
        self.path = Path(path)
        self.session = open_session(self.path, threads, "ONNX appearance model")
        inputs, outputs = self.session.get_inputs(), self.session.get_outputs()
        if len(inputs) != 1 or len(inputs[0].shape) != 4 or len(outputs[0].shape) != 2:
            raise ValueError(f"{self.path}: expected crops (n, 3, h, w) in and embeddings (n, d) out")
        check_image_input(self.path, inputs[0], "crop", "BGR in [0, 1]")
        _, _, h, w = inputs[0].shape
        self.crop_size = (w, h) if isinstance(w, int) and isinstance(h, int) else (64, 32)
        d = outputs[0].shape[1]
        self.input_name = inputs[0].name
        self.batch = batch
        self.dim = d if isinstance(d, int) else int(self.embed(np.zeros((1, h, w, 3), np.uint8)).shape[1])

    def __call__(self, image: np.ndarray, xywh: np.ndarray) -> np.ndarray:
        """``(n, dim)`` L2-normalised embeddings of boxes ``xywh (n, 4)`` (pixels) of BGR ``image``."""
        return self.embed(crop_boxes(image, xywh, self.crop_size))

    def embed(self, crops: np.ndarray) -> np.ndarray:
        """``(n, dim)`` L2-normalised embeddings of BGR uint8 crops ``(n, h, w, 3)`` of the model's size."""
        crops = np.asarray(crops)
        if len(crops) == 0:
            return np.zeros((0, getattr(self, "dim", 0)))
        out = []
        for i in range(0, len(crops), self.batch):
            x = np.ascontiguousarray(crops[i : i + self.batch].transpose(0, 3, 1, 2), dtype=np.float32)
            x *= np.float32(1 / 255)
            out.append(self.session.run(None, {self.input_name: x})[0])
        emb = np.concatenate(out).astype(float)
        return emb / np.maximum(np.linalg.norm(emb, axis=1, keepdims=True), 1e-12)


__all__ = ["LEARNED_MODEL", "OnnxAppearance"]
