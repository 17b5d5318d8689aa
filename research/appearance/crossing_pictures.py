"""Before/after pictures of a crossing for docs/howto/identities-on-video.md: a development arena (seed 3, rule.md's
development seeds) tracked with ``--online`` (motion only, frame by frame) and with the default (the look learned from
the video); three moments around the first swap the online run makes, one row per run, each animal's box in its id's
colour, ids numbered as the animals they follow for most of the video (so a swap shows as a change of colour).
Usage: python research/appearance/crossing_pictures.py docs/images/crossing.jpg"""

from __future__ import annotations

import subprocess
import sys
import tempfile
from pathlib import Path

import cv2
import numpy as np
from scipy.optimize import linear_sum_assignment

from lookalike.io.arena_files import write_arena
from lookalike.viz.annotate import draw_box, draw_label
from lookalike.viz.colors import identity_colour

SEED, CROP, STEP = 3, 200, 8


def track(video: Path, extra: list[str], out: Path) -> np.ndarray:
    subprocess.run([sys.executable, "-m", "lookalike", "track", "--video", str(video), "--detector", "blob", "-t",
                    "boxtrack", "--targets", "8", *extra, "-o", str(out)], check=True, stdout=subprocess.DEVNULL)
    return np.loadtxt(out, delimiter=",", ndmin=2)


def nearest_ids(rows: np.ndarray, truth: np.ndarray) -> np.ndarray:
    """Per truth row, the result id whose box centre is nearest within 15 px (0: none)."""
    out = np.zeros(len(truth), int)
    centres = rows[:, 2:4] + rows[:, 4:6] / 2
    for k, (f, x, y) in enumerate(zip(truth[:, 0], truth[:, 2], truth[:, 3])):
        sel = np.flatnonzero(rows[:, 0] == f)
        if len(sel):
            d = np.hypot(centres[sel, 0] - x, centres[sel, 1] - y)
            out[k] = int(rows[sel[np.argmin(d)], 1]) if d.min() <= 15 else 0
    return out


def mapping(ids: np.ndarray, truth: np.ndarray) -> dict[int, int]:
    """Truth id -> the result id it is matched to most often."""
    counts = np.zeros((9, 9))
    np.add.at(counts, (truth[:, 1].astype(int), ids), 1)
    a, b = linear_sum_assignment(-counts[1:, 1:])
    return {int(i) + 1: int(j) + 1 for i, j in zip(a, b)}


def panel(files, rows: np.ndarray, frame: int, centre: np.ndarray, title: str) -> np.ndarray:
    image = files.arena.frame(frame).copy()
    for r in rows[rows[:, 0] == frame]:
        draw_box(image, r[2:6], identity_colour(int(r[1])), label=str(int(r[1])))
    x0, y0 = (np.clip(centre - CROP // 2, 0, np.array(image.shape[1::-1]) - CROP)).astype(int)
    crop = cv2.resize(image[y0:y0 + CROP, x0:x0 + CROP], (2 * CROP, 2 * CROP), interpolation=cv2.INTER_NEAREST)
    draw_label(crop, title, (8, 22), (255, 255, 255), scale=0.6)
    return crop


def main(output: Path) -> None:
    work = Path(tempfile.mkdtemp())
    files = write_arena(work / "arena", seed=SEED)
    truth = np.loadtxt(files.gt, delimiter=",", ndmin=2)
    truth = np.column_stack([truth[:, :2], truth[:, 2:4] + truth[:, 4:6] / 2])
    online = track(files.video, ["--online"], work / "online.txt")
    look = track(files.video, [], work / "look.txt")
    ids_on, ids_look = nearest_ids(online, truth), nearest_ids(look, truth)
    map_on, map_look = mapping(ids_on, truth), mapping(ids_look, truth)
    wrong_on = ids_on != np.array([map_on[int(t)] for t in truth[:, 1]])
    right_look = ids_look == np.array([map_look[int(t)] for t in truth[:, 1]])
    for k in np.flatnonzero(wrong_on & right_look & (truth[:, 0] > 2 * STEP)):
        f, animal = int(truth[k, 0]), int(truth[k, 1])
        before = np.flatnonzero((truth[:, 0] == f - 2 * STEP) & (truth[:, 1] == animal))
        if len(before) and not wrong_on[before[0]] and (wrong_on[(truth[:, 1] == animal) & (truth[:, 0] >= f) &
                                                                  (truth[:, 0] < f + STEP)]).all():
            break
    else:
        raise SystemExit("no crossing where the online run swaps and the learned look does not")
    for rows, ids in ((online, map_on), (look, map_look)):  # ids as the animals they follow most: a swap shows
        back = {j: i for i, j in ids.items()}
        rows[:, 1] = [back.get(int(r), 0) for r in rows[:, 1]]
    frames = (f - 2 * STEP, f - STEP // 2, f + STEP)
    centre = truth[np.isin(truth[:, 0], frames) & (truth[:, 1] == animal), 2:4].mean(axis=0)
    rows = [np.hstack([panel(files, r, g, centre, f"{name}, frame {g}") for g in frames])
            for r, name in ((online, "--online"), (look, "learned look"))]
    picture = np.vstack(rows)
    cv2.imwrite(str(output), cv2.resize(picture, (900, 600), interpolation=cv2.INTER_AREA),
                [cv2.IMWRITE_JPEG_QUALITY, 85])
    print(f"wrote {output}: arena seed {SEED}, animal {animal} around frame {f}")


if __name__ == "__main__":
    main(Path(sys.argv[1]))
