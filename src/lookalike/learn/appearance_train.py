"""Training the diver appearance embedding (torch) as an identity classifier with an additive cosine margin, and its
ONNX export: ``(n, 3, 32, 64)`` BGR crops in ``[0, 1]`` -> L2-normalised embeddings."""

from __future__ import annotations

import json
import math
import os
import shutil
import tempfile
import time
from collections.abc import Callable
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

import numpy as np

from lookalike._optional import needs
from lookalike.learn.appearance_data import CROP_SIZE, CropSet, diver_crops
from lookalike.learn.device import torch_device

MODEL_NAME = "diver_reid"


@dataclass(frozen=True)
class AppearanceTrainConfig:
    """Training set-up of the appearance model (the JSON written beside the weights holds it)."""

    scenarios: int = 24  # training scenarios (new divers)
    frames: int = 300  # frames per training scenario
    every: int = 3  # crop every n-th frame
    embedding: int = 32
    channels: int = 16  # channels of the first block (doubling up to 4x)
    epochs: int = 24
    batch_size: int = 128
    learning_rate: float = 3e-3
    weight_decay: float = 5e-4
    margin: float = 0.25  # additive cosine margin
    scale: float = 16.0  # logit scale
    seed: int = 0
    threads: int = 1
    device: str = "cpu"
    minutes: float | None = None  # stop after this wall time
    validation_every: int = 10  # validation crops from every n-th frame
    match_thresholds: bool = True  # store the trackers' thresholds matched to the model (validation scenarios)

    def __post_init__(self) -> None:
        for name in ("scenarios", "frames", "every", "embedding", "channels", "epochs", "batch_size", "threads",
                     "validation_every"):
            if getattr(self, name) < 1:
                raise ValueError(f"{name} must be at least 1, got {getattr(self, name)}")


def _torch() -> Any:
    with needs("torch"):
        import torch
    return torch


def build_net(embedding: int = 32, channels: int = 16) -> Any:
    """The embedding network (a ``torch.nn.Module``; input ``(n, 3, 32, 64)`` BGR in [0, 1])."""
    torch = _torch()
    nn = torch.nn

    def block(cin: int, cout: int, pool: bool) -> list[Any]:
        layers = [nn.Conv2d(cin, cout, 3, padding=1, bias=False), nn.BatchNorm2d(cout), nn.ReLU(inplace=True)]
        return layers + [nn.MaxPool2d(2)] if pool else layers

    c = channels

    class EmbeddingNet(nn.Module):  # type: ignore[misc, name-defined]
        def __init__(self) -> None:
            super().__init__()
            self.body = nn.Sequential(*block(3, c, True), *block(c, 2 * c, True), *block(2 * c, 4 * c, True),
                                      *block(4 * c, 4 * c, False))
            self.head = nn.Linear(4 * c, embedding)

        def forward(self, x: Any) -> Any:
            z = self.body((x - 0.35) / 0.25).mean(dim=(2, 3))
            return torch.nn.functional.normalize(self.head(z), dim=1)

    return EmbeddingNet()


def augment(x: Any, generator: Any) -> Any:
    """Augmented copy of a batch ``(b, 3, h, w)`` in [0, 1]: flip, scale/shift, colour, murk, blur."""
    torch = _torch()
    F = torch.nn.functional
    b = x.shape[0]

    def u(lo: float, hi: float, *shape: int) -> Any:
        return lo + (hi - lo) * torch.rand(*shape, generator=generator, device=x.device)

    flip = u(0, 1, b) < 0.5
    x = torch.where(flip[:, None, None, None], x.flip(-1), x)
    s = u(0.85, 1.15, b)
    theta = torch.zeros(b, 2, 3, device=x.device)
    theta[:, 0, 0] = s
    theta[:, 1, 1] = s * u(0.9, 1.1, b)
    theta[:, :, 2] = u(-0.08, 0.08, b, 2)
    x = F.grid_sample(x, F.affine_grid(theta, list(x.shape), align_corners=False), padding_mode="border",
                      align_corners=False)
    mean = x.mean(dim=(1, 2, 3), keepdim=True)
    x = (x - mean) * u(0.7, 1.3, b, 1, 1, 1) + mean * u(0.8, 1.2, b, 1, 1, 1)
    x = x * u(0.8, 1.2, b, 3, 1, 1)
    water = u(0.1, 0.8, b, 3, 1, 1)
    alpha = u(0, 0.45, b, 1, 1, 1) * (u(0, 1, b, 1, 1, 1) < 0.6)
    x = (1 - alpha) * x + alpha * water + u(0, 0.04, b, 1, 1, 1) * torch.randn(x.shape, generator=generator,
                                                                              device=x.device)
    sigma = float(u(0.5, 1.6, 1))
    k = torch.exp(-(torch.arange(5, device=x.device) - 2.0) ** 2 / (2 * sigma**2))
    k = k / k.sum()
    kernel = (k[:, None] * k[None, :]).expand(3, 1, 5, 5)
    blurred = F.conv2d(F.pad(x, (2, 2, 2, 2), mode="replicate"), kernel, groups=3)
    x = torch.where((u(0, 1, b) < 0.5)[:, None, None, None], blurred, x)
    return x.clamp(0, 1)


def to_tensor_input(crops: np.ndarray) -> np.ndarray:
    """``(n, 3, h, w)`` float32 in [0, 1] from BGR uint8 crops ``(n, h, w, 3)`` (the ONNX input layout)."""
    return np.ascontiguousarray(np.asarray(crops, dtype=np.float32).transpose(0, 3, 1, 2) / 255.0)


def verification_auc(emb: np.ndarray, labels: np.ndarray) -> float:
    """ROC AUC of cosine similarity separating same-label from different-label pairs of ``emb (n, d)``."""
    sim = emb @ emb.T
    iu = np.triu_indices(len(emb), 1)
    same = (labels[:, None] == labels[None, :])[iu]
    score = sim[iu]
    if same.all() or not same.any():
        raise ValueError("verification_auc: need both same- and different-label pairs")
    order = np.argsort(score, kind="stable")
    ranks = np.empty(len(score))
    ranks[order] = np.arange(1, len(score) + 1)
    n_pos, n_neg = int(same.sum()), int((~same).sum())
    return float((ranks[same].sum() - n_pos * (n_pos + 1) / 2) / (n_pos * n_neg))


def train_appearance(config: AppearanceTrainConfig, output: Path,
                     log: Callable[[str], None] = print) -> dict[str, Any]:
    """Train, keep the best validation epoch, write ``output/diver_reid.onnx`` and ``.json`` (both made aside and
    renamed into place at the end, so an interrupted run leaves an earlier model whole); the JSON dict."""
    torch = _torch()
    from lookalike.sim.divers import VALIDATION_SCENARIOS
    from lookalike.sim.divers_train import training_scenarios

    start = time.perf_counter()
    torch.manual_seed(config.seed)
    torch.set_num_threads(config.threads)
    device = torch_device(config.device)
    train = diver_crops(training_scenarios(config.scenarios, config.frames), every=config.every, seed=config.seed)
    val = diver_crops(VALIDATION_SCENARIOS, every=config.validation_every, jitter=0.05, seed=config.seed + 1)
    ids, labels = np.unique(train.labels, return_inverse=True)
    log(f"{len(train.labels)} training crops of {len(ids)} divers; {len(val.labels)} validation crops "
        f"({time.perf_counter() - start:.0f} s)")
    x_all = torch.from_numpy(to_tensor_input(train.crops)).to(device)
    y_all = torch.from_numpy(labels.astype(np.int64)).to(device)
    net = build_net(config.embedding, config.channels).to(device)
    weight = torch.nn.Parameter(torch.randn(len(ids), config.embedding, device=device) * 0.1)
    params = [*net.parameters(), weight]
    opt = torch.optim.AdamW(params, lr=config.learning_rate, weight_decay=config.weight_decay)
    steps = config.epochs * math.ceil(len(y_all) / config.batch_size)
    sched = torch.optim.lr_scheduler.OneCycleLR(opt, max_lr=config.learning_rate, total_steps=steps)
    gen = torch.Generator(device=device).manual_seed(config.seed)
    history: list[dict[str, float]] = []
    best: tuple[float, dict[str, Any]] = (-1.0, {})
    for epoch in range(config.epochs):
        net.train()
        perm = torch.randperm(len(y_all), generator=gen, device=device)
        total = 0.0
        for i in range(0, len(perm), config.batch_size):
            idx = perm[i : i + config.batch_size]
            emb = net(augment(x_all[idx], gen))
            cos = emb @ torch.nn.functional.normalize(weight, dim=1).T
            onehot = torch.nn.functional.one_hot(y_all[idx], len(ids)).float()
            loss = torch.nn.functional.cross_entropy(config.scale * (cos - config.margin * onehot), y_all[idx])
            opt.zero_grad()
            loss.backward()
            opt.step()
            sched.step()
            total += float(loss.detach()) * len(idx)
        auc = verification_auc(embed(net, val.crops, device), val.labels)
        history.append({"epoch": epoch + 1, "loss": total / len(y_all), "val_auc": auc,
                        "minutes": (time.perf_counter() - start) / 60})
        log(f"epoch {epoch + 1}: loss {total / len(y_all):.3f}, validation AUC {auc:.4f} "
            f"({history[-1]['minutes']:.1f} min)")
        if auc > best[0]:
            best = (auc, {k: v.detach().clone() for k, v in net.state_dict().items()})
        if config.minutes is not None and history[-1]["minutes"] >= config.minutes:
            log(f"stopping after {config.minutes} min")
            break
    net.load_state_dict(best[1])
    output.mkdir(parents=True, exist_ok=True)
    staging = Path(tempfile.mkdtemp(prefix=".train-appearance-", dir=output))  # no JSON of an earlier model beside it
    try:
        onnx_path = export_onnx(net.cpu(), staging / f"{MODEL_NAME}.onnx")
        info: dict[str, Any] = {
            "model": f"{MODEL_NAME}.onnx",
            "input": {"name": "crops", "layout": "NCHW", "channels": "BGR", "range": [0, 1],
                      "width": CROP_SIZE[0], "height": CROP_SIZE[1]},
            "output": {"name": "embedding", "dim": config.embedding, "normalised": True},
            "config": asdict(config),
            "training": {"crops": int(len(train.labels)), "identities": int(len(ids)),
                         "scenario_seeds": sorted({int(v) // 10 for v in ids})},
            "validation": {"scenarios": [s.name for s in VALIDATION_SCENARIOS], "crops": int(len(val.labels)),
                           "best_auc": best[0]},
            "history": history,
            "minutes": (time.perf_counter() - start) / 60,
            "torch": str(torch.__version__),
        }
        if config.match_thresholds:
            from lookalike.sim.divers_run import HANDCRAFTED_THRESHOLDS, matched_thresholds
            from lookalike.vision.appearance_onnx import OnnxAppearance

            model = OnnxAppearance(onnx_path)
            info["matched_thresholds"] = {t: matched_thresholds(model, t) for t in HANDCRAFTED_THRESHOLDS}
        onnx_path.with_suffix(".json").write_text(json.dumps(info, indent=1))
        for name in (f"{MODEL_NAME}.onnx", f"{MODEL_NAME}.json"):  # the earlier model stays whole until here
            os.replace(staging / name, output / name)
    finally:
        shutil.rmtree(staging, ignore_errors=True)
    log(f"best validation AUC {best[0]:.4f} → {output / f'{MODEL_NAME}.onnx'}")
    return info


def embed(net: Any, crops: np.ndarray, device: Any = "cpu", batch: int = 512) -> np.ndarray:
    """Embeddings ``(n, d)`` of BGR uint8 crops with the torch network (evaluation mode)."""
    torch = _torch()
    net.eval()
    with torch.no_grad():
        return np.concatenate([net(torch.from_numpy(to_tensor_input(crops[i : i + batch])).to(device)).cpu().numpy()
                               for i in range(0, len(crops), batch)])


def export_onnx(net: Any, path: Path) -> Path:
    """Write ``net`` as ONNX (input ``crops (n, 3, 32, 64)``, output ``embedding (n, d)``, dynamic ``n``)."""
    torch = _torch()
    import warnings

    net.eval()
    dummy = torch.zeros(2, 3, CROP_SIZE[1], CROP_SIZE[0])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        torch.onnx.export(net, (dummy,), str(path), input_names=["crops"], output_names=["embedding"],
                          dynamic_axes={"crops": {0: "n"}, "embedding": {0: "n"}}, opset_version=17, dynamo=False)
    return path


__all__ = ["MODEL_NAME", "AppearanceTrainConfig", "CropSet", "augment", "build_net", "embed", "export_onnx",
           "train_appearance", "verification_auc"]
