"""Typed parameter schemas for components: frozen dataclasses built from YAML mappings.

A component declares ``Params``, a frozen dataclass whose fields use :func:`param`
(default + one-line description). :func:`parse_params` turns a YAML mapping into an
instance, rejecting unknown keys (with the closest valid name) and wrong types.
"""
from __future__ import annotations

import contextlib
import dataclasses
import difflib
import math
import types
import typing
from typing import Any, Mapping

from .errors import ConfigError, clip, shown


def param(default: Any, help: str, choices: tuple | None = None) -> Any:
    """A dataclass field with a default, a one-line description and optional choices."""
    meta = {"help": help}
    if choices is not None:
        meta["choices"] = tuple(choices)
    if isinstance(default, (list, dict, set)):
        raise TypeError(f"param({default!r}, {help!r}): a default must be immutable (use a tuple)")
    return dataclasses.field(default=default, metadata=meta)


@dataclasses.dataclass(frozen=True)
class NoParams:
    """A component without parameters."""


def closest(name: str, options) -> str:
    """' (did you mean X?)' for the closest option, or ''."""
    match = difflib.get_close_matches(str(name), [str(o) for o in options], n=1)
    return f" (did you mean '{match[0]}'?)" if match else ""


def _coerce(value: Any, kind: Any, where: str) -> Any:
    """``value`` checked against the annotation ``kind`` (and converted where YAML is loose)."""
    origin = typing.get_origin(kind)
    if kind is Any:
        return value
    if origin in (typing.Union, types.UnionType):
        args = [a for a in typing.get_args(kind) if a is not type(None)]
        return None if value is None else _coerce(value, args[0], where)
    if origin in (tuple, list) or kind in (tuple, list):
        return _coerce_sequence(value, kind, where)
    coerce = _SCALAR_COERCERS.get(kind)
    return coerce(value, where) if coerce else value


def _coerce_sequence(value: Any, kind: Any, where: str) -> tuple:
    if not isinstance(value, (list, tuple)):
        raise ConfigError(f"{where}: expected a list, got {shown(value)}")
    args = typing.get_args(kind)
    if typing.get_origin(kind) is tuple and args and Ellipsis not in args:  # tuple[X, Y]: exactly these items
        if len(value) != len(args):
            raise ConfigError(f"{where}: expected a list of {len(args)} values, got {shown(value)}")
        return tuple(_coerce(v, a, f"{where}[{i}]") for i, (v, a) in enumerate(zip(value, args)))
    item = args[0] if args else Any
    return tuple(_coerce(v, item, f"{where}[{i}]") for i, v in enumerate(value))


def _coerce_bool(value: Any, where: str) -> bool:
    if isinstance(value, bool):
        return value
    raise ConfigError(f"{where}: expected true or false, got {shown(value)}")


def _coerce_int(value: Any, where: str) -> int:
    if isinstance(value, int) and not isinstance(value, bool):
        return value
    if isinstance(value, float) and value.is_integer():
        return int(value)
    raise ConfigError(f"{where}: expected an integer, got {shown(value)}")


def _coerce_float(value: Any, where: str) -> float:
    number = None
    if isinstance(value, (int, float)) and not isinstance(value, bool):
        with contextlib.suppress(OverflowError):  # an int beyond float's range: not finite
            number = float(value)
        if number is None:
            number = math.inf
    elif isinstance(value, str):  # YAML 1.1 reads '1e-3' as a string
        with contextlib.suppress(ValueError):
            number = float(value)
    if number is None:
        raise ConfigError(f"{where}: expected a number, got {shown(value)}")
    if not math.isfinite(number):
        raise ConfigError(f"{where}: expected a finite number, got {shown(value)}")
    return number


def _coerce_str(value: Any, where: str) -> str:
    if isinstance(value, str):
        return value
    raise ConfigError(f"{where}: expected a string, got {shown(value)}")


_SCALAR_COERCERS = {bool: _coerce_bool, int: _coerce_int, float: _coerce_float, str: _coerce_str}

_SCALARS = (bool, int, float, str)


def _supported(kind: Any) -> bool:
    """Whether :func:`_coerce` checks values of this annotation."""
    origin = typing.get_origin(kind)
    if kind is Any or kind in _SCALARS or kind in (tuple, list):
        return True
    if origin in (typing.Union, types.UnionType):
        args = [a for a in typing.get_args(kind) if a is not type(None)]
        return len(args) == 1 and _supported(args[0])
    if origin in (tuple, list):
        return all(_supported(a) for a in typing.get_args(kind) if a is not Ellipsis)
    return False


def check_schema(schema: type) -> None:
    """A ConfigError if a ``Params`` field has no default, an annotation that parameters cannot be
    checked against, or a default that its own checks refuse (caught when a component registers)."""
    try:
        hints = typing.get_type_hints(schema)
    except Exception as exc:
        raise ConfigError(f"Params annotations cannot be resolved: {exc}") from None
    defaults = {}
    for f in dataclasses.fields(schema):
        if f.default is dataclasses.MISSING:
            raise ConfigError(f"parameter '{f.name}' has no default (give every field param(default, help))")
        if not _supported(hints[f.name]):
            raise ConfigError(f"parameter '{f.name}': annotation {hints[f.name]!r} is not supported; use bool, "
                              f"int, float, str, Any, tuple, tuple[X, ...], tuple[X, Y] or X | None "
                              f"(for a set of allowed values: param(..., choices=...))")
        defaults[f.name] = f.default
    parse_params(schema, defaults, "default Params")


def fields(schema: type) -> list[dict]:
    """Describe a schema: name, type, default, help and choices of each field."""
    hints = typing.get_type_hints(schema)
    out = []
    for f in dataclasses.fields(schema):
        out.append({
            "name": f.name,
            "type": getattr(hints[f.name], "__name__", str(hints[f.name])),
            "default": f.default,
            "help": f.metadata.get("help", ""),
            "choices": f.metadata.get("choices"),
        })
    return out


def parse_params(schema: type, values: Mapping[str, Any] | None, where: str) -> Any:
    """Build ``schema`` from ``values``; ``where`` (e.g. 'dr2track.yaml: label') prefixes errors."""
    if values is not None and not isinstance(values, Mapping):
        raise ConfigError(f"{where}: expected a mapping of parameters, got {shown(values)}")
    values = dict(values or {})
    hints = typing.get_type_hints(schema)
    known = {f.name: f for f in dataclasses.fields(schema)}
    unknown = [k for k in values if k not in known]
    if unknown:
        k = unknown[0]
        valid = ", ".join(known) or "none"
        raise ConfigError(f"{where}: unknown parameter {shown(k)}{closest(k, known)}; valid parameters: {valid}")
    kwargs = {}
    for name, value in values.items():
        key = f"{where}.{clip(str(name))}"
        kwargs[name] = _coerce(value, hints[name], key)
        choices = known[name].metadata.get("choices")
        if choices is not None and kwargs[name] not in choices:
            raise ConfigError(f"{key}: {shown(kwargs[name])} is not one of {', '.join(map(str, choices))}"
                              f"{closest(kwargs[name], choices)}")
    try:
        instance = schema(**kwargs)
    except (TypeError, ValueError) as exc:
        raise ConfigError(f"{where}: {exc}") from None
    check = getattr(instance, "validate", None)
    if check is not None:
        try:
            problem = check()
        except Exception as exc:
            raise ConfigError(f"{where}: invalid parameters ({schema.__qualname__}.validate() raised "
                              f"{type(exc).__name__}{': ' + str(exc) if str(exc) else ''})") from None
        if problem:
            raise ConfigError(f"{where}: {problem}")
    return instance
