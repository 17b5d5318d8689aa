"""Scoring loops shared by the development harnesses (dev5.py to dev17.py): each takes ``run(video, n)``, which
returns one result table per mode, and prints one line per video and a paired summary against the first mode."""
import importlib.util
import subprocess
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "benchmarks"))
from _common import SHARED_DATA  # noqa: E402
from video_identities import identity_scores  # noqa: E402

from lookalike.bench.datasets import read_hexbug_points  # noqa: E402
from lookalike.eval import evaluate_points  # noqa: E402
from lookalike.io.arena_files import write_arena  # noqa: E402
from lookalike.io.video_frames import source_frames  # noqa: E402
from lookalike.pipeline.blob_detections import BlobRows, auto_blob_config, cached_blob_detections  # noqa: E402
from lookalike.trackers.offline.closed_set import track_closed_set  # noqa: E402
from lookalike.vision.blob_auto import BOX_TRACKER_PARAMS  # noqa: E402

HEXBUG_RADIUS_PX = 120.0


def detected(video: Path, n: int, work: Path) -> tuple[BlobRows, float]:
    """The blobs of ``video`` with the settings estimated for ``n`` animals (cached under ``work``), and its frame
    rate."""
    found = cached_blob_detections(video, auto_blob_config(video, [], n)[0], cache=work / "cache")
    return found, source_frames(video)[2] or 25.0


def module_at(commit: str, path: str, work: Path):
    """The package module at ``path`` (e.g. src/lookalike/trackers/offline/appearance.py) as of ``commit``, read from
    git and loaded under a name of its own (``<stem>_<commit>``), for a baseline beside the working tree's."""
    root = Path(__file__).resolve().parents[2]
    text = subprocess.run(["git", "-C", str(root), "show", f"{commit}:{path}"], capture_output=True, text=True,
                          check=True).stdout
    name = f"{Path(path).stem}_{commit}"
    (work / f"{name}.py").write_text(text)
    spec = importlib.util.spec_from_file_location(name, work / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module
    spec.loader.exec_module(module)
    return module


def with_each(found: BlobRows, fps: float, n: int, module, name: str, values) -> list[np.ndarray]:
    """The closed set (the command's parameters, with the look and the parts) once per value of ``module.name``,
    restored afterwards."""
    kept, out = getattr(module, name), []
    try:
        for value in values:
            setattr(module, name, value)
            out.append(track_closed_set(found.rows, n, fps, n_frames=found.frames, online=dict(BOX_TRACKER_PARAMS),
                                        shapes=found.shapes, parts=found.parts))
    finally:
        setattr(module, name, kept)
    return out


def with_looks(found: BlobRows, fps: float, n: int, modules) -> list[np.ndarray]:
    """The closed set (as :func:`with_each`) once with each appearance module's look (``fit_identity_space`` and
    ``with_appearance``, patched into the closed set and restored afterwards)."""
    import lookalike.trackers.offline.closed_set as closed_set

    out = []
    for module in modules:
        kept = closed_set.with_appearance
        closed_set.with_appearance = module.with_appearance
        try:
            out += with_each(found, fps, n, closed_set, "fit_identity_space", [module.fit_identity_space])
        finally:
            closed_set.with_appearance = kept
    return out


def main(run, modes, work: Path, seeds=(*range(10), *range(4000, 4020))) -> None:
    """``dev*.py [arenas,hexbug]``: the arenas ``seeds`` and the HexBug clips, each mode against the first."""
    which = sys.argv[1].split(",") if len(sys.argv) > 1 else ["arenas", "hexbug"]
    if "arenas" in which:
        summary(f"arenas {seeds[0]}-{seeds[-1]} ({len(seeds)})", arenas(seeds, run, modes, work), modes)
    if "hexbug" in which:
        summary("hexbug", hexbug(run, modes), modes)


def arenas(seeds, run, modes, work: Path) -> np.ndarray:
    """IDF1 (15 px) per arena seed and mode."""
    table = []
    for seed in seeds:
        files = write_arena(work / f"arena{seed}", seed=seed)
        truth = np.loadtxt(files.gt, delimiter=",", ndmin=2)
        ref = np.column_stack([truth[:, :2], truth[:, 2:4] + truth[:, 4:6] / 2])
        n = len(np.unique(truth[:, 1]))
        row = [identity_scores(r, ref, n)["IDF1"] for r in run(files.video, n)]
        table.append(row)
        print(f"arena {seed}: " + " ".join(f"{m} {v:.4f}" for m, v in zip(modes, row)), flush=True)
    return np.array(table)


def hexbug(run, modes) -> np.ndarray:
    """IDF1 (within 120 px of the head) per HexBug clip and mode."""
    table = []
    for video in sorted((SHARED_DATA / "hexbug").glob("*.mp4")):
        img = next(iter(source_frames(video)[0]))
        gt = read_hexbug_points(video.with_suffix(".csv"), (img.shape[1], img.shape[0]))
        n = len(np.unique(gt[1]))
        row = []
        for rows in run(video, n):
            c = rows[:, 2:4] + rows[:, 4:6] / 2
            m = evaluate_points(gt[0], gt[1], gt[2], rows[:, 0].astype(int), rows[:, 1].astype(int), c,
                                radius=HEXBUG_RADIUS_PX, num_frames=101)
            row.append(m["IDF1"])
        table.append(row)
        print(f"hexbug {video.stem} (N={n}): " + " ".join(f"{m} {v:.4f}" for m, v in zip(modes, row)), flush=True)
    return np.array(table)


def summary(name: str, t: np.ndarray, modes) -> None:
    """Each mode's mean and its paired difference from the first mode's (standard error, seeds up and down)."""
    for j in range(1, len(modes)):
        d = t[:, j] - t[:, 0]
        print(f"{name}: {modes[0]} {t[:, 0].mean():.4f} {modes[j]} {t[:, j].mean():.4f} diff {d.mean():+.4f} "
              f"(se {d.std(ddof=1) / np.sqrt(len(d)):.4f}; up {(d > 0).sum()}, down {(d < 0).sum()})")


def with_parts(video: Path, n: int, work: Path, parts: dict) -> list[np.ndarray]:
    """The closed set (the command's parameters, with the look and the parts) once per ``blob_parts`` function of
    ``parts`` (mode name -> function, patched into ``blob_shape`` and restored afterwards), each mode detecting
    through a cache folder of its own under ``work``; rows and shape vectors are checked to be the same in all."""
    from lookalike.vision import blob_shape

    config, fps = auto_blob_config(video, [], n, cache=work / "cache")[0], source_frames(video)[2] or 25.0
    kept, out, first = blob_shape.blob_parts, [], None
    try:
        for mode, function in parts.items():
            blob_shape.blob_parts = function
            found = cached_blob_detections(video, config, cache=work / f"cache-{mode}")
            first = first or found
            assert np.array_equal(first.rows, found.rows) and np.array_equal(first.shapes, found.shapes)
            out.append(track_closed_set(found.rows, n, fps, n_frames=found.frames, online=dict(BOX_TRACKER_PARAMS),
                                        shapes=found.shapes, parts=found.parts))
    finally:
        blob_shape.blob_parts = kept
    return out
