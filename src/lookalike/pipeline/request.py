"""A ``lookalike track`` run as data: its inputs and outputs, checked together, and the branch they select."""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

from lookalike.io.outputs import check_outputs, refuse_inputs


@dataclass(frozen=True)
class TrackRequest:
    """What ``lookalike track`` was asked: ``output``, the input (``path``, ``video`` text, ``detections``,
    ``points`` or ``bag``), the ``detector`` and its ``blob`` settings, the robots ``pipeline`` and ``reports``,
    ``annotate`` and ``save_detections`` outputs, the ``tracker`` name, ``targets`` (0: an open set), ``offline``
    (None: the default), a live source's stops (``max_frames``, ``seconds`` of stream time); how to track: the
    tracker's ``settings`` (``KEY=VALUE``) and ``params_file``, ``min_score``, ``fps`` (None: the input's),
    appearance ``features``, the health checks' ``team_size`` (None: ``targets``) and ``health_window`` (frames),
    the detection files' ``det_format`` and whether seqinfo.ini's seqLength bounds them (``use_length``); for robots
    from pixels the ``detector_model`` and ``heading_model`` (None: shipped), and a bag's ``camera_topic`` and
    comma-separated ``heading_topics``; ``output_folder``: the output was given ending in ``/`` (a folder, which
    only a folder of sequences is tracked into). Every check raises ``ValueError`` naming the options."""

    output: Path
    tracker: str = "sort"
    path: Path | None = None
    video: str | None = None
    detections: Path | None = None
    points: Path | None = None
    bag: Path | None = None
    detector: str | None = None
    blob: list[str] = field(default_factory=list)
    pipeline: str | None = None
    reports: Path | None = None
    annotate: Path | None = None
    save_detections: Path | None = None
    targets: int | None = None
    offline: bool | None = None
    max_frames: int | None = None
    seconds: float | None = None
    settings: list[str] = field(default_factory=list)
    params_file: Path | None = None
    min_score: float = -math.inf
    fps: float | None = None
    features: str = "video"
    team_size: int | None = None
    health_window: int = 15
    det_format: str = "auto"
    use_length: bool = True
    detector_model: Path | None = None
    heading_model: Path | None = None
    camera_topic: str | None = None
    heading_topics: str | None = None
    output_folder: bool = False

    @property
    def video_path(self) -> Path | None:
        return Path(self.video) if self.video is not None else None

    @property
    def health_team_size(self) -> int | None:
        """The team size the health checks expect: ``team_size``, else ``targets`` (None: unknown)."""
        return self.team_size if self.team_size is not None else self.targets or None

    def live(self) -> str | None:
        """``video``'s text when it names a live source (a camera index, a stream URL), else None."""
        from lookalike.io.sources import is_live

        live = self.video if is_live(self.video) else None
        if self.save_detections is not None and (self.detector is None or live is not None):
            raise ValueError("--save-detections: only with --video FILE --detector")
        if live is None and (self.max_frames is not None or self.seconds is not None):
            raise ValueError("--max-frames/--seconds: only with a live --video (a camera index or a stream URL)")
        if live is not None and self.detector is None:
            raise ValueError(f"--video {live}: a live source needs --detector blob or --detector FILE.onnx")
        return live

    def branch(self) -> str:
        """Which branch the options select: ``pipeline``, ``points``, ``blobs``, ``video`` or ``files``."""
        branch = self._branch()
        if self.output_folder and not (branch == "files" and self.path is not None and self.path.is_dir()):
            what = "a single detection file" if branch == "files" else "this input"
            raise ValueError(f"-o/--output {self.output}/: a folder (it ends in '/'), but {what} is tracked into one "
                             f"result file; give a file name, e.g. {self.output / 'tracks.txt'} (nothing was written)")
        if self.features != "video" and branch not in ("video", "blobs"):
            raise ValueError(f"--features {self.features}: only with --video (features come from the pixels)")
        return branch

    def _branch(self) -> str:
        path, video, det, detector, blob = self.path, self.video, self.detections, self.detector, self.blob
        if self.bag is not None:
            if any(x is not None for x in (path, video, det, self.points, self.reports, detector)) or blob:
                raise ValueError("--bag: the bag is the input; drop PATH/--video/--detections/--points/--reports/"
                                 "--detector/--blob")
            return "pipeline"
        if self.points is not None:
            if any(x is not None for x in (path, det, detector, self.pipeline)) or blob:
                raise ValueError("--points: the points are the input; drop PATH/--detections/--detector/--blob/"
                                 "--pipeline")
            if video is not None and self.annotate is None:
                raise ValueError("--points --video: the video is only drawn on, with --annotate")
            return "points"
        if self.pipeline is not None:
            if detector is not None or blob or det is not None or path is not None:
                raise ValueError("--pipeline: finds its own detections; drop --detector/--blob/--detections/PATH")
            return "pipeline"
        if detector is not None or blob:
            if video is None or det is not None or path is not None or detector is None:
                raise ValueError("--detector/--blob: use --video FILE --detector blob, without det.txt")
            return "blobs"
        if video is not None:
            if (det or path) is None or (det is not None and path is not None):
                raise ValueError("--video: give the detections once, as --detections det.txt (or as PATH)")
            return "video"
        if self.annotate is not None or det is not None:
            raise ValueError("--annotate/--detections: only with --video")
        if path is None:
            raise ValueError("PATH: give det.txt, a sequence folder or a folder of sequences (or --video with "
                             "--detections)")
        return "files"

    def is_offline(self, branch: str, live: str | None) -> bool:
        """Whether the N identities are decided over the whole sequence: as asked, else by default on a blob video
        tracked by ``boxtrack`` with ``targets``."""
        targets = self.targets or None
        offline = bool(self.offline) if self.offline is not None else (
            targets is not None and self.detector == "blob" and self.tracker == "boxtrack" and live is None
            and self.bag is None)
        if offline and live is not None:
            raise ValueError(f"--video {live}: a live source; drop --offline (see the live camera how-to)")
        if offline and targets is None:
            raise ValueError("--offline: needs --targets N (the known number of targets)")
        if offline and branch == "pipeline":
            raise ValueError("--offline: not with --pipeline (the robots' identities come from their reports, frame "
                             "by frame)")
        if offline and self.tracker != "boxtrack":
            raise ValueError(f"--offline: the closed set's online pass is boxtrack; use -t boxtrack, not "
                             f"{self.tracker!r}")
        return offline

    def check_outputs(self, inputs: list[Path | None]) -> None:
        """``ValueError`` when the result, a file written beside it, ``annotate`` or ``save_detections`` is one of
        ``inputs`` or another output."""
        output = self.output
        siblings = [output.with_name(output.stem + s) for s in (".health.csv", ".merges.csv")]
        files = [p for p in inputs if p is not None and p.is_file()]
        extra = {k: v for k, v in (("--annotate", self.annotate), ("--save-detections", self.save_detections))
                 if v is not None}
        refuse_inputs([output, *siblings], files)
        if extra:
            check_outputs({"-o/--output": output, **{f"-o/--output's {s.name}": s for s in siblings}, **extra},
                          files, input_folders=[self.video_path])  # (video: an image folder)


__all__ = ["TrackRequest"]
