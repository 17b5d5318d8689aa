"""mkdocs hook: a nav entry whose path is a glob (``trackers/*.md``) lists the matching pages.

Pages other parts of the project add (one note per tracker) then appear in the navigation without
editing ``mkdocs.yml``; each page's title is its first heading. A glob that matches nothing fails
the build.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any


def _expand(item: Any, docs_dir: Path) -> Any:
    if isinstance(item, list):
        return [_expand(x, docs_dir) for x in item]
    if isinstance(item, dict):
        return {k: _expand(v, docs_dir) for k, v in item.items()}
    if isinstance(item, str) and "*" in item:
        pages = sorted(p.relative_to(docs_dir).as_posix() for p in docs_dir.glob(item))
        if not pages:
            raise ValueError(f"mkdocs.yml nav: no page matches {item!r} under {docs_dir}")
        return pages
    return item


def on_config(config: Any) -> Any:
    """Expand glob paths in ``nav`` into the pages they match."""
    config["nav"] = _expand(config["nav"], Path(config["docs_dir"]))
    return config
