"""Plain option values (``str``, ``list[str]``, in-bounds numbers, ``Path`` text) converted with typer's rules but
without building a pydantic ``TypeAdapter`` per parameter (a fifth of a short command's CPU time); the rest by typer."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

_MISSING = object()


def _plain_value(annotation: Any, info: Any, value: Any, param: Any, ctx: Any) -> Any:
    """The converted value where it needs no pydantic, else ``_MISSING``."""
    if getattr(info, "parser", None) is not None or getattr(info, "click_type", None) is not None:
        return _MISSING
    kind = type(value)
    if annotation is str:
        return value if kind is str else _MISSING
    if annotation in (int, float):
        if kind is not annotation or getattr(info, "clamp", False):
            return _MISSING
        low, high = getattr(info, "min", None), getattr(info, "max", None)
        if value != value or (low is not None and value < low) or (high is not None and value > high):
            return _MISSING
        return value
    if annotation in (list[str], list[Path]):
        if kind not in (list, tuple) or not all(type(v) is str for v in value):
            return _MISSING
        if annotation == list[str]:
            return list(value)
        items = [_plain_value(Path, info, v, param, ctx) for v in value]
        return _MISSING if any(v is _MISSING for v in items) else items
    if annotation is Path and kind is str and not getattr(info, "allow_dash", False) \
            and getattr(info, "path_type", None) is None:
        from typer._param_types import coerce_cli_path

        return coerce_cli_path(Path(value), info, path_type=Path, param=param, ctx=ctx)
    return _MISSING


def install() -> bool:
    """Make typer convert plain option values without pydantic; False, changing nothing, where typer's
    internals are not the expected ones."""
    try:
        import typer.core as core
        from typer._coercion import RuntimeParam
    except ImportError:
        return False
    found = getattr(core, "build_runtime_param", None)
    if found is None or getattr(found, "_lookalike_quick", False):
        return found is not None
    full_builder: Any = found

    @dataclass(frozen=True)
    class QuickRuntimeParam(RuntimeParam):  # type: ignore[misc]
        """Converts plain values directly; builds typer's own converter for anything else."""

        descriptor: Any = None
        _full: list[Any] = field(default_factory=list)

        def _coerce_value(self, value: Any, param: Any, ctx: Any) -> Any:
            plain = _plain_value(self.annotation, self.parameter_info, value, param, ctx)
            if plain is not _MISSING:
                return plain
            if not self._full:
                self._full.append(full_builder(self.descriptor))
            return self._full[0]._coerce_value(value, param=param, ctx=ctx)

    def quick_builder(descriptor: Any) -> Any:
        if getattr(descriptor, "file_annotation", None) is not None:
            return full_builder(descriptor)
        return QuickRuntimeParam(parameter_info=descriptor.parameter_info, annotation=descriptor.annotation,
                                 descriptor=descriptor)

    quick_builder._lookalike_quick = True  # type: ignore[attr-defined]
    quick_builder._full_builder = full_builder  # type: ignore[attr-defined]
    core.build_runtime_param = quick_builder
    return True
