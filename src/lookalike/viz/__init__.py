"""Visual output: drawing on frames, videos and GIFs, plots, the HTML report and the demo scenes (OpenCV, matplotlib and
Pillow imported lazily)."""

from lookalike.io.video_frames import read_frames, video_info
from lookalike.viz.annotate import (
    LabelSpace,
    Tails,
    draw_box,
    draw_box_tracks,
    draw_caption,
    draw_label,
    draw_legend,
    draw_tail,
)
from lookalike.viz.colors import identity_colour, rgb_hex
from lookalike.viz.plots import birdseye_plot, grouped_bar_chart
from lookalike.viz.report import HtmlReport
from lookalike.viz.video import VideoWriter, write_gif

__all__ = [
    "HtmlReport",
    "LabelSpace",
    "Tails",
    "VideoWriter",
    "birdseye_plot",
    "draw_box",
    "draw_box_tracks",
    "draw_caption",
    "draw_label",
    "draw_legend",
    "draw_tail",
    "grouped_bar_chart",
    "identity_colour",
    "read_frames",
    "rgb_hex",
    "video_info",
    "write_gif",
]
