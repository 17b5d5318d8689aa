"""Development runs of research/appearance/rule.md (arena seeds 0-9, HexBug): online closed set (the CLI), offline
closed set without and with the learned look (library, the CLI's parameters). Not a confirmation run."""
import sys
import tempfile
from pathlib import Path

import numpy as np
import scoring  # (puts benchmarks/ on the path)
from video_identities import run_track

from lookalike.trackers.offline.closed_set import track_closed_set
from lookalike.vision.blob_auto import BOX_TRACKER_PARAMS

work = Path(tempfile.mkdtemp(prefix="appearance-dev-"))
MODES = ("online", "offline", "offline+look")


def run(video: Path, n: int):
    """The online closed set (the command), then the offline one without and with the learned look (the package,
    the command's parameters; the package as it now is, without the merged blobs' parts)."""
    online, _ = run_track(video, n, ["--online"], work / f"{video.stem}-online.txt", work / "cache")
    found, fps = scoring.detected(video, n, work)
    return [online, *(track_closed_set(found.rows, n, fps, n_frames=found.frames, online=dict(BOX_TRACKER_PARAMS),
                                       shapes=found.shapes if use else None) for use in (False, True))]


def summary(name, t):
    d1, d2 = t[:, 2] - t[:, 1], t[:, 2] - t[:, 0]
    se = lambda d: d.std(ddof=1) / np.sqrt(len(d))  # noqa: E731
    print(f"{name}: mean online {t[:, 0].mean():.4f} offline {t[:, 1].mean():.4f} offline+look {t[:, 2].mean():.4f}; "
          f"look-offline {d1.mean():+.4f} (se {se(d1):.4f}); look-online {d2.mean():+.4f} (se {se(d2):.4f})")


if __name__ == "__main__":
    which = sys.argv[1:] or ["arenas", "hexbug"]
    if "arenas" in which:
        summary("arenas 0-9", scoring.arenas(range(10), run, MODES, work))
    if "hexbug" in which:
        summary("hexbug", scoring.hexbug(run, MODES))
