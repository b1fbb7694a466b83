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

from dcfkit.errors import ConfigError, clip, shown


def _number(value: float) -> str:
    """``value`` as a bound is written: ``10000``, ``0.5``, ``1e+10`` (exact: repr where %g rounds)."""
    if isinstance(value, int):
        return str(value)
    return f"{value:g}" if float(f"{value:g}") == value else repr(value)


@dataclasses.dataclass(frozen=True)
class Bounds:
    """The values a numeric parameter may take, declared with :func:`param`'s ``ge``, ``gt``,
    ``le`` and ``lt``: from ``low`` to ``high``, each end included unless it is open."""

    low: float = -math.inf
    high: float = math.inf
    low_open: bool = False
    high_open: bool = False

    def __contains__(self, value: Any) -> bool:
        above = value > self.low if self.low_open else value >= self.low
        return above and (value < self.high if self.high_open else value <= self.high)

    def __str__(self) -> str:
        """``[1, 10000]``, ``(0, 1]``, ``> 0``, ``<= 10``."""
        if self.high == math.inf:
            return f"{'>' if self.low_open else '>='} {_number(self.low)}"
        if self.low == -math.inf:
            return f"{'<' if self.high_open else '<='} {_number(self.high)}"
        return (f"{'(' if self.low_open else '['}{_number(self.low)}, {_number(self.high)}"
                f"{')' if self.high_open else ']'}")

    def requirement(self) -> str:
        """What a value must be, for a message: ``in [1, 10000]``, ``> 0``."""
        two_sided = self.low != -math.inf and self.high != math.inf
        return f"in {self}" if two_sided else str(self)


def _bounds(ge: Any, gt: Any, le: Any, lt: Any) -> Bounds | None:
    """The :class:`Bounds` that ``param``'s limits declare, or None; TypeError if they cannot hold."""
    given = {k: v for k, v in (("ge", ge), ("gt", gt), ("le", le), ("lt", lt)) if v is not None}
    if not given:
        return None
    if any(isinstance(v, bool) or not isinstance(v, (int, float)) or math.isnan(v) for v in given.values()) \
            or ("ge" in given and "gt" in given) or ("le" in given and "lt" in given):
        raise TypeError(f"param limits {given}: numbers, at most one of ge and gt and one of le and lt")
    bounds = Bounds(given.get("ge", given.get("gt", -math.inf)), given.get("le", given.get("lt", math.inf)),
                    "gt" in given, "lt" in given)
    if bounds.low > bounds.high:
        raise TypeError(f"param limits {given}: no value is within them")
    return bounds


def param(default: Any, help: str, choices: tuple | None = None, *, ge: float | None = None,
          gt: float | None = None, le: float | None = None, lt: float | None = None) -> Any:
    """A dataclass field with a default, a one-line description, optional choices and, for a
    number, optional bounds: ``ge`` (>=), ``gt`` (>), ``le`` (<=), ``lt`` (<). A value outside
    them is a ConfigError naming the key; ``dcfkit components`` lists them."""
    meta = {"help": help}
    if choices is not None:
        meta["choices"] = tuple(choices)
    if (bounds := _bounds(ge, gt, le, lt)) is not None:
        meta["bounds"] = bounds
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


def coerce(value: Any, kind: Any, where: str) -> Any:
    """``value`` checked against the annotation ``kind`` (and converted where YAML is loose); a
    :class:`ConfigError` naming ``where`` otherwise. Specs' own keys are read with it too."""
    origin = typing.get_origin(kind)
    if kind is Any:
        return value
    if origin in (typing.Union, types.UnionType):
        args = [a for a in typing.get_args(kind) if a is not type(None)]
        return None if value is None else coerce(value, args[0], where)
    if origin in (tuple, list) or kind in (tuple, list):
        return _coerce_sequence(value, kind, where)
    scalar = _SCALAR_COERCERS.get(kind)
    return scalar(value, where) if scalar else value


def _coerce_sequence(value: Any, kind: Any, where: str) -> tuple:
    if not isinstance(value, (list, tuple)):
        raise ConfigError(f"{where}: expected a list, got {shown(value)}")
    args = typing.get_args(kind)
    if typing.get_origin(kind) is tuple and args and Ellipsis not in args:  # tuple[X, Y]: exactly these items
        if len(value) != len(args):
            raise ConfigError(f"{where}: expected a list of {len(args)} values, got {shown(value)}")
        return tuple(coerce(v, a, f"{where}[{i}]") for i, (v, a) in enumerate(zip(value, args)))
    item = args[0] if args else Any
    return tuple(coerce(v, item, f"{where}[{i}]") for i, v in enumerate(value))


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


def _numeric(kind: Any) -> bool:
    """Whether values of this annotation are numbers (or None): what bounds apply to."""
    if typing.get_origin(kind) in (typing.Union, types.UnionType):
        args = [a for a in typing.get_args(kind) if a is not type(None)]
        return len(args) == 1 and _numeric(args[0])
    return kind in (int, float)


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
        if "bounds" in f.metadata and not _numeric(hints[f.name]):
            raise ConfigError(f"parameter '{f.name}': bounds (ge, gt, le, lt) need an int or float annotation, "
                              f"not {hints[f.name]!r}")
        defaults[f.name] = f.default
    parse_params(schema, defaults, "default Params")


def fields(schema: type) -> list[dict]:
    """Describe a schema: name, type, default, help, choices and bounds (``[1, 10000]``,
    ``> 0``; None without) of each field."""
    hints = typing.get_type_hints(schema)
    out = []
    for f in dataclasses.fields(schema):
        out.append({
            "name": f.name,
            "type": getattr(hints[f.name], "__name__", str(hints[f.name])),
            "default": f.default,
            "help": f.metadata.get("help", ""),
            "choices": f.metadata.get("choices"),
            "bounds": str(f.metadata["bounds"]) if "bounds" in f.metadata else None,
        })
    return out


def _checked(field: dataclasses.Field, value: Any, kind: Any, where: str) -> Any:
    """``value`` of ``field`` coerced to its annotation ``kind`` and checked against its choices
    and bounds (a ConfigError naming ``where`` and the field otherwise)."""
    key = f"{where}.{clip(field.name)}"
    value = coerce(value, kind, key)
    choices = field.metadata.get("choices")
    if choices is not None and value not in choices:
        raise ConfigError(f"{key}: {shown(value)} is not one of {', '.join(map(str, choices))}"
                          f"{closest(value, choices)}")
    bounds = field.metadata.get("bounds")
    if bounds is not None and value is not None and value not in bounds:
        raise ConfigError(f"{where}: {field.name} must be {bounds.requirement()}, got {shown(value)}")
    return value


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
    kwargs = {name: _checked(known[name], value, hints[name], where) for name, value in values.items()}
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
