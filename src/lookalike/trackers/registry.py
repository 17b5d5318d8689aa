"""Trackers registered by name, so that the CLI and benchmarks can build them from strings."""

from __future__ import annotations

import dataclasses
import typing
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from lookalike.trackers.base import Range

_REGISTRY: dict[str, type] = {}


class UnknownTrackerError(KeyError, ValueError):
    """An unknown tracker name: a ``ValueError`` like every bad input, and still the ``KeyError`` it used to be. Its
    text is the message itself (a ``KeyError`` alone would print it quoted)."""

    def __str__(self) -> str:
        return str(self.args[0]) if self.args else ""


@dataclass(frozen=True)
class ParameterInfo:
    """One tracker parameter: name, type name, default value, description and the values it allows
    (``range``, ``choices``; None: any value of its type)."""

    name: str
    type: str
    default: Any
    doc: str
    range: Range | None = None
    choices: tuple[Any, ...] | None = None

    def allowed(self) -> str:
        """The allowed values in words: ``[0, 1]``, ``one of 'a', 'b'``, ``(0, inf) or None``, ``true/false``."""
        if self.range is not None:
            text = str(self.range)
        elif self.choices is not None:
            text = "one of " + ", ".join(map(repr, self.choices))
        else:
            text = "true/false" if self.type == "bool" else ("text" if self.type.startswith("str") else "any")
        return f"{text} or None" if "None" in self.type else text


def register_tracker(name: str) -> Callable[[type], type]:
    """Class decorator: register a tracker class (which has a ``Config`` dataclass) under ``name``; ``ValueError`` for a
    name already taken, by another registered class or by a built-in tracker (:data:`BUILTIN_TRACKERS`)."""

    def decorate(cls: type) -> type:
        from lookalike.trackers.base import name_config

        if name in _REGISTRY and _REGISTRY[name] is not cls:
            raise ValueError(f"a tracker named {name!r} is already registered")
        if BUILTIN_TRACKERS.get(name, cls.__module__) != cls.__module__:  # (before its module is imported)
            raise ValueError(f"{name!r} is the name of a built-in tracker; register {cls.__name__} under another")
        if not dataclasses.is_dataclass(getattr(cls, "Config", None)):
            raise TypeError(f"tracker {name!r} needs a dataclass attribute 'Config'")
        setattr(cls, "name", name)  # noqa: B010 (a class attribute the protocol declares)
        name_config(getattr(cls, "Config"), name)  # noqa: B009 (checked above)
        _REGISTRY[name] = cls
        return cls

    return decorate


def tracker_names() -> list[str]:
    """Names of all registered trackers, sorted: the built-in ones (:data:`BUILTIN_TRACKERS`), the
    plugins' entry-point names and any registered since, without importing a tracker module."""
    return sorted(set(BUILTIN_TRACKERS) | set(_plugin_entry_points()) | set(_REGISTRY))


def tracker_class(name: str) -> type:
    """The class registered under ``name``; unknown names raise :class:`UnknownTrackerError` (a ``ValueError``, and a
    ``KeyError``) listing the known ones.
    Only the module that registers ``name`` is imported (every one for an unknown name)."""
    if name not in _REGISTRY:
        module = BUILTIN_TRACKERS.get(name) or _plugin_entry_points().get(name)
        if module is not None:
            import importlib

            importlib.import_module(module)
        if name not in _REGISTRY:
            _load_builtin()
    try:
        return _REGISTRY[name]
    except KeyError:
        raise UnknownTrackerError(f"unknown tracker {name!r}; registered: {', '.join(sorted(_REGISTRY))}") from None


def _config_class(name: str) -> Any:
    return getattr(tracker_class(name), "Config")  # noqa: B009 (checked at registration)


def tracker_parameters(name: str) -> list[ParameterInfo]:
    """The parameters of tracker ``name`` with their defaults and descriptions (:class:`UnknownTrackerError` for an
    unknown ``name``, as :func:`tracker_class`)."""
    from lookalike.trackers.base import field_specs

    config_cls = _config_class(name)
    return [ParameterInfo(f.name, getattr(hint, "__name__", str(hint)),
                          f.default if f.default_factory is dataclasses.MISSING else f.default_factory(),
                          f.metadata.get("doc", ""), bounds, choices)
            for f, (_, hint, bounds, choices) in zip(dataclasses.fields(config_cls), field_specs(config_cls))]


def make_tracker(name: str, **params: Any) -> Any:
    """Build tracker ``name`` with config overrides; an unknown parameter, or a value outside its
    declared type, range or choices (:func:`~lookalike.trackers.base.param`), raises ``ValueError``
    (``TypeError`` for a wrong type) in one line naming the tracker and the parameter. An unknown
    ``name`` raises :class:`UnknownTrackerError`, a ``ValueError`` (and a ``KeyError``), listing the known ones
    (:func:`tracker_class`)."""
    from lookalike.trackers.base import check_value, field_specs

    config_cls = _config_class(name)
    known = {spec[0]: spec[1:] for spec in field_specs(config_cls)}
    unknown = sorted(set(params) - set(known))
    if unknown:
        raise ValueError(f"tracker {name!r} has no parameter(s) {unknown}; known: {sorted(known)}")
    for key, value in params.items():
        check_value(name, key, value, *known[key])
    return tracker_class(name)(config_cls(**params))


def parse_parameter(name: str, assignment: str) -> tuple[str, Any]:
    """Parse ``KEY=VALUE`` for tracker ``name``, converting VALUE to the parameter's type and checking
    it against the declared range or choices (``ValueError`` in one line otherwise)."""
    from lookalike.trackers.base import check_value, field_specs

    if "=" not in assignment:
        raise ValueError(f"expected KEY=VALUE, got {assignment!r}")
    key, text = (part.strip() for part in assignment.split("=", 1))
    known = {spec[0]: spec[1:] for spec in field_specs(_config_class(name))}
    if key not in known:
        raise ValueError(f"tracker {name!r} has no parameter {key!r}; known: {sorted(known)}")
    hint = known[key][0]
    value = _convert(name, key, text, hint)
    try:
        check_value(name, key, value, *known[key])
    except TypeError as exc:
        raise ValueError(str(exc)) from None
    return key, value


def _convert(name: str, key: str, text: str, hint: Any) -> Any:
    args = [a for a in typing.get_args(hint) if a is not type(None)]
    if args and text.lower() in ("none", "null"):
        return None
    target = args[0] if args else hint
    try:
        if target is bool:
            if text.lower() in ("1", "true", "yes", "on"):
                return True
            if text.lower() in ("0", "false", "no", "off"):
                return False
            raise ValueError(text)
        if target in (int, float, str):
            return target(text)
    except ValueError:
        raise ValueError(f"tracker {name!r}: {key}: cannot read {text!r} as {target.__name__}") from None
    raise ValueError(f"tracker {name!r}: parameter {key!r} of type {hint} cannot be set from text")


BUILTIN_TRACKERS = {
    "boxtrack": "lookalike.trackers.boxtrack",
    "deepsort": "lookalike.trackers.deepsort",
    "diversort": "lookalike.trackers.diversort",
    "jpda": "lookalike.trackers.jpda",
    "kalman_ha": "lookalike.trackers.kalman_ha",
    "kalman_ha2": "lookalike.trackers.kalman_ha",
    "lstm": "lookalike.trackers.lstm.tracker",
    "set": "lookalike.trackers.set.tracker",
    "sort": "lookalike.trackers.sort",
}
"""The trackers of this layer and the module that registers each (tests check the list is complete),
so that :func:`tracker_names` needs no tracker module imported."""

ENTRY_POINT_GROUP = "lookalike.trackers"
"""Other packages add trackers through entry points of this group (name = "module:Class"); the package itself
declares none: every shipped tracker is built in."""

_PLUGINS_LOADED = False
_plugins: dict[str, str] | None = None


def _plugin_entry_points() -> dict[str, str]:
    """Entry-point name -> module of group ``lookalike.trackers`` (read once)."""
    global _plugins
    if _plugins is None:
        from importlib.metadata import entry_points

        _plugins = {ep.name: ep.module for ep in entry_points(group=ENTRY_POINT_GROUP)}
    return _plugins


def _load_builtin() -> None:
    """Register the built-in trackers and the plugins (the entry points of group ``lookalike.trackers``)."""
    global _PLUGINS_LOADED
    if _PLUGINS_LOADED:
        return
    import importlib

    modules = set(BUILTIN_TRACKERS.values()) | set(_plugin_entry_points().values())
    for module in sorted(modules):
        importlib.import_module(module)
    _PLUGINS_LOADED = True
