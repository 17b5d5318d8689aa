"""A single HTML report: headings, text, tables, images embedded as ``data:`` URIs, and videos embedded the same way up
to :data:`EMBED_MAX_BYTES` (larger ones linked by relative path, to be kept beside the report)."""

from __future__ import annotations

import base64
import html
import math
import os
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

from lookalike.viz.colors import BGR, rgb_hex

_MIME = {".png": "image/png", ".gif": "image/gif", ".jpg": "image/jpeg", ".jpeg": "image/jpeg"}
EMBED_MAX_BYTES = 8_000_000  # a larger video is linked, not embedded (base64 adds a third)

_STYLE = """
body { font-family: system-ui, sans-serif; max-width: 1100px; margin: 2em auto; padding: 0 1em; color: #222; }
h1 { font-size: 1.6em; } h2 { margin-top: 1.8em; border-bottom: 1px solid #ddd; }
table { border-collapse: collapse; margin: 0.8em 0; font-size: 0.9em; }
th, td { padding: 3px 10px; border-bottom: 1px solid #e4e4e4; }
th { background: #f4f4f4; text-align: left; } td.num { text-align: right; font-variant-numeric: tabular-nums; }
figure { display: inline-block; margin: 0.6em 1em 0.6em 0; vertical-align: top; }
figure img, figure video { max-width: 100%; border: 1px solid #ccc; } figcaption { font-size: 0.85em; color: #555; }
.note { color: #555; font-size: 0.9em; }
.legend { font-size: 0.85em; margin: 0 0 4px; padding: 5px 8px; box-sizing: border-box; display: flex;
          flex-wrap: wrap; gap: 4px 16px; background: #202020; color: #eee; max-width: 100%; }
.legend span { display: inline-flex; align-items: center; gap: 6px; }
.legend i { display: inline-block; width: 22px; height: 11px; border: 3px solid; }
"""


def _cell(value: Any) -> tuple[str, bool]:
    if isinstance(value, bool) or value is None:
        return html.escape(str(value)), False
    if isinstance(value, int):
        return f"{value:,}", True
    if isinstance(value, float):
        return ("—" if math.isnan(value) else f"{value:,.3f}".rstrip("0").rstrip(".")), True
    return html.escape(str(value)), False


def _data_uri(path: Path | str, mimes: Mapping[str, str], what: str) -> str:
    """The file at ``path`` as a ``data:`` URI; ValueError for a missing file or a suffix not in ``mimes``."""
    p = Path(path)
    mime = mimes.get(p.suffix.lower())
    if mime is None:
        raise ValueError(f"{what}: unsupported type {p.suffix!r} of {p} (use {', '.join(mimes)})")
    if not p.is_file():
        raise ValueError(f"{what}: no such file {p}")
    return f"data:{mime};base64,{base64.b64encode(p.read_bytes()).decode('ascii')}"


def _href(target: Path | str, relative_to: Path | str | None) -> str:
    """``target``'s path relative to the folder ``relative_to`` (if given), escaped for an attribute."""
    href = os.path.relpath(target, relative_to) if relative_to is not None else str(target)
    return html.escape(Path(href).as_posix(), quote=True)


class HtmlReport:
    """Collects report blocks in order; :meth:`write` saves one HTML file."""

    def __init__(self, title: str) -> None:
        self.title = title
        self._blocks: list[str] = []

    def heading(self, text: str) -> None:
        """A section heading."""
        self._blocks.append(f"<h2>{html.escape(text)}</h2>")

    def text(self, text: str, note: bool = False) -> None:
        """A paragraph (plain text, escaped)."""
        cls = ' class="note"' if note else ""
        self._blocks.append(f"<p{cls}>{html.escape(text)}</p>")

    def table(self, rows: Sequence[Mapping[str, Any]], columns: Sequence[str] | None = None,
              caption: str = "") -> None:
        """A table of ``rows`` (dicts) with ``columns`` (default: the first row's keys)."""
        if not rows:
            self.text(f"{caption}: no rows." if caption else "No rows.", note=True)
            return
        cols = list(columns or rows[0].keys())
        out = ["<table>"]
        if caption:
            out.append(f"<caption>{html.escape(caption)}</caption>")
        out.append("<tr>" + "".join(f"<th>{html.escape(str(c))}</th>" for c in cols) + "</tr>")
        for r in rows:
            cells = []
            for c in cols:
                text, numeric = _cell(r.get(c, ""))
                cells.append(f'<td class="num">{text}</td>' if numeric else f"<td>{text}</td>")
            out.append("<tr>" + "".join(cells) + "</tr>")
        out.append("</table>")
        self._blocks.append("\n".join(out))

    def image(self, path: Path | str, caption: str = "", width: int | None = None) -> None:
        """Embed the image file at ``path`` (PNG, GIF or JPEG) with a caption."""
        src = _data_uri(path, _MIME, "image")
        style = f' style="width:{int(width)}px"' if width else ""
        alt = html.escape(caption or Path(path).name, quote=True)
        self._blocks.append(
            f'<figure><img src="{src}" alt="{alt}"{style}>'
            f"<figcaption>{html.escape(caption)}</figcaption></figure>"
        )

    def link(self, target: Path | str, text: str, relative_to: Path | str | None = None) -> None:
        """A link to ``target`` (e.g. a video), written relative to the folder ``relative_to``."""
        self._blocks.append(f'<p><a href="{_href(target, relative_to)}">{html.escape(text)}</a></p>')

    def video(self, target: Path | str, caption: str, relative_to: Path | str | None = None,
              width: int | None = None, poster: Path | str | None = None,
              legend: Sequence[tuple[str, BGR, bool]] = ()) -> bool:
        """An inline player for the MP4 at ``target``: embedded when it is at most :data:`EMBED_MAX_BYTES`, else
        linked (path relative to the folder ``relative_to``); the caption links the file and says which. ``poster``:
        an image embedded as the picture shown before playing; ``legend``: ``(text, BGR colour, dashed)`` keys shown
        above the player, clear of its controls. Returns whether the video was embedded."""
        if not Path(target).is_file():
            raise ValueError(f"video: no such file {target}")
        href = _href(target, relative_to)
        embedded = Path(target).stat().st_size <= EMBED_MAX_BYTES
        src = _data_uri(target, {".mp4": "video/mp4"}, "video") if embedded else href
        style = f' style="width:{int(width)}px"' if width else ""
        cover = f' poster="{_data_uri(poster, _MIME, "poster")}"' if poster is not None else ""
        keys = "".join(f'<span><i style="border-color:{rgb_hex(c)};border-style:{"dashed" if d else "solid"}"></i>'
                       f"{html.escape(t)}</span>" for t, c, d in legend)
        where = "embedded here; also" if embedded else "played from"
        name = html.escape(Path(target).name)
        self._blocks.append(
            "<figure>" + (f'<div class="legend"{style}>{keys}</div>' if keys else "")
            + f'<video controls muted playsinline preload="auto" src="{src}"{cover}{style}></video>'
            f'<figcaption>{html.escape(caption)} ({where} <a href="{href}">{name}</a>, a file beside this report)'
            "</figcaption></figure>"
        )
        return embedded

    def code(self, text: str) -> None:
        """A preformatted block (commands to try)."""
        self._blocks.append(f"<pre>{html.escape(text)}</pre>")

    def render(self) -> str:
        """The whole HTML document."""
        return (
            "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">"
            f"<title>{html.escape(self.title)}</title><style>{_STYLE}</style></head><body>\n"
            f"<h1>{html.escape(self.title)}</h1>\n" + "\n".join(self._blocks) + "\n</body></html>\n"
        )

    def write(self, path: Path | str) -> Path:
        """Write the document to ``path`` atomically (a temporary file renamed into place)."""
        from lookalike.io.outputs import write_atomic

        return write_atomic(path, self.render())
