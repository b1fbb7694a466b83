"""What each component hook must return, checked on every call (docs/plugins.md, section 5).

A kind's base class declares its hooks' checks in its :class:`~dcfkit.registry.Contract`
(``returns``); :func:`checked`, applied by :meth:`Registry.build <dcfkit.registry.Registry.build>`
to every component it builds, replaces each hook of the instance by a :class:`Hook` that
calls it, then checks what it returned: type, shape, dtype, finiteness and range. A
violation, or an exception the hook raised, is a :class:`ContractViolation` naming the
component, the plugin that provided it and the hook; the tracker adds the frame. So a plugin
scale estimator returning -1 stops the run where it did, instead of writing negative boxes.

A check is a function ``(returned, args, component) -> what is wrong, or None``; the
builders below make the common ones.
"""
from __future__ import annotations

import functools
import math
import numbers
from typing import Any, Callable, Mapping

import numpy as np

from dcfkit.errors import DcfkitError, RegistryError, TrackingError, describe_error, shown

Check = Callable[[Any, tuple, Any], "str | None"]


class ContractViolation(TrackingError):
    """A component hook returned what its contract forbids, or raised (the message names the
    component, its provider and the hook)."""


class Hook:
    """A component's hook as the tracker calls it: the original, then its check."""

    def __init__(self, component: Any, hook: str, check: Check | None, where: str):
        self.original = getattr(component, hook)
        self.component, self.hook, self.check, self.where = component, hook, check, where

    def __call__(self, *args):
        try:
            returned = self.original(*args)
        except DcfkitError:
            raise
        except Exception as exc:  # a component's bug, named
            raise ContractViolation(f"{self.where}: {self.hook}() raised {describe_error(exc)}") from exc
        if self.check is not None:
            problem = self.check(returned, args, self.component)
            if problem is not None:
                raise ContractViolation(f"{self.where}: {self.hook}() returned {problem}")
        return returned


def checked(component: Any, provider: str, hooks: Mapping[str, Check | None]) -> Any:
    """``component`` with each of ``hooks`` (name -> check, None: only named when it raises)
    replaced by a :class:`Hook`; returns it."""
    where = f"{component.kind} '{component.name}' (from {provider})"
    for hook, check in hooks.items():
        if callable(getattr(component, hook, None)) and not isinstance(getattr(component, hook), Hook):
            try:
                setattr(component, hook, Hook(component, hook, check, where))
            except AttributeError:  # __slots__, or a read-only property in its place
                raise RegistryError(f"{where}: dcfkit cannot check its {hook}(): its instances take no attribute "
                                    f"{hook!r} (drop __slots__)") from None
    return component


def naming_the_frame(frame_of: Callable[[Any], int]):
    """Decorates a tracker method so that a :class:`ContractViolation` it raises names the
    frame, ``frame_of(tracker)``."""
    def decorate(method):
        @functools.wraps(method)
        def named(tracker, *args):
            try:
                return method(tracker, *args)
            except ContractViolation as exc:
                raise ContractViolation(f"frame {frame_of(tracker)}: {exc}") from exc.__cause__
        return named
    return decorate


# -- the checks ------------------------------------------------------------------------------

KIND_NAMES = {"f": "real floats", "iu": "integers", "iuf": "real numbers", "c": "complex numbers"}


def array(shape: Callable[[tuple, Any], tuple] | tuple | None = None, *, kinds: str = "f", finite: bool = True,
          nonnegative: bool = False, largest: float = math.inf) -> Check:
    """An ndarray (not a list, nor a subclass such as a masked array, whose hidden values numpy
    still computes with) of ``shape`` (a tuple, None for any size along an axis, or a function
    of the hook's arguments and the component), of a dtype kind in ``kinds``, finite
    (``finite``; else at least not NaN), >= 0 (``nonnegative``) and at most ``largest`` in size."""
    def check(value, args, component):
        if type(value) is not np.ndarray:
            return f"a {type(value).__name__}, expected a numpy array of {KIND_NAMES.get(kinds, kinds)}"
        expected = shape(args, component) if callable(shape) else shape
        if expected is not None and (value.ndim != len(expected) or any(
                e is not None and s != e for s, e in zip(value.shape, expected))):
            sizes = ", ".join("N" if e is None else str(e) for e in expected)
            return f"shape {value.shape}, expected ({sizes}{',' * (len(expected) == 1)})"
        if value.dtype.kind not in kinds:
            return f"dtype {value.dtype}, expected {KIND_NAMES.get(kinds, kinds)}"
        problem = _values_problem(value, finite, nonnegative)
        if problem is None and largest < math.inf and value.size and np.abs(value).max() > largest:
            problem = f"values as large as {np.abs(value).max():.3g}, expected at most {largest:g} in size"
        return problem
    return check


def _values_problem(value: np.ndarray, finite: bool, nonnegative: bool) -> str | None:
    if value.dtype.kind in "fc":  # one pass over the values: finite ones hold no NaN
        if finite:
            if not np.isfinite(value).all():
                return "NaN or infinite values"
        elif np.isnan(value).any():
            return "NaN values"
    if nonnegative and value.size and value.min() < 0:
        return f"negative values (min {value.min():g}), expected >= 0"
    return None


def scalar(lowest: float, highest: float, *, above: bool = False, inf: bool = False,
           integer: bool = False) -> Check:
    """One real number (a Python or numpy scalar, or a 0-d array) in ``[lowest, highest]``
    (``(lowest, highest]`` if ``above``), or ``inf`` if ``inf``; an integer if ``integer``."""
    interval = f"{'(' if above else '['}{lowest:g}, {highest:g}]{' or inf' if inf else ''}"

    def check(value, args, component):
        if type(value) is np.ndarray and value.ndim == 0:
            value = value[()]
        wanted = numbers.Integral if integer else numbers.Real
        if isinstance(value, bool) or not isinstance(value, wanted):
            return f"{shown(value)}, expected {'an integer' if integer else 'a real number'} in {interval}"
        value = float(value)
        if value == math.inf and inf:
            return None
        if math.isnan(value) or not (lowest < value if above else lowest <= value) or value > highest:
            return f"{value!r}, expected {interval}"
        return None
    return check


def pair(first: Check, second: Check, names: tuple[str, str]) -> Check:
    """A tuple of two, each with its check."""
    def check(value, args, component):
        if not (isinstance(value, tuple) and len(value) == 2):
            return f"a {type(value).__name__}, expected a tuple ({names[0]}, {names[1]})"
        for name, part, part_check in zip(names, value, (first, second)):
            problem = part_check(part, args, component)
            if problem is not None:
                return f"{name} of {problem}" if problem.startswith(("shape", "dtype")) else f"{name}: {problem}"
        return None
    return check


MAX_FACTOR = 10.0  # a search factor: the built-in estimators span at most x10 each way


def search_factors(value, args, component) -> str | None:
    """One or more finite numbers in [1/MAX_FACTOR, MAX_FACTOR] in a 1-d array (the scales to
    search, relative to the current one)."""
    problem = array((None,), kinds="iuf")(value, args, component)
    if problem is None:  # the sample budget was checked for the first call's count
        first = component.__dict__.setdefault("_contract_factor_count", value.size)
        if value.size > first:
            return f"{value.size} factors, more than the {first} of its first call (the memory budget's)"
    tolerance = 1 + 1e-9  # step ** k of the built-ins may round past 10
    if problem is None and not (value.size and ((value * MAX_FACTOR * tolerance >= 1)
                                                & (value <= MAX_FACTOR * tolerance)).all()):
        problem = f"{shown(value)}, expected one or more numbers in [{1 / MAX_FACTOR:g}, {MAX_FACTOR:g}]"
    return problem


def finite_arrays(value, args, component) -> str | None:
    """Any value; the numpy arrays it is or holds (a tuple, list or dict of them) finite.
    For what only the component reads back (a solver's model)."""
    parts = value.values() if isinstance(value, dict) else value if isinstance(value, (tuple, list)) else (value,)
    for part in parts:
        if isinstance(part, np.ndarray) and part.dtype.kind in "fc" and not np.isfinite(part).all():
            return "NaN or infinite values"
    return None


def within_grid(value, args, component) -> str | None:
    """Distractor offsets: (N, 2) integer (dy, dx) cells, each inside the label grid ``args[0]``."""
    if isinstance(value, np.ndarray) and value.size == 0:
        return None  # none (any empty array: the tracker reads it as (0, 2))
    problem = array((None, 2), kinds="iu")(value, args, component)
    if problem is None and value.size:
        height, width = args[0].shape
        dy, dx = value[:, 0], value[:, 1]  # compared, not abs(): abs of the most negative int64 is negative
        if ((dy <= -height) | (dy >= height) | (dx <= -width) | (dx >= width)).any():
            far = np.abs(value.astype(np.float64)).max(axis=0)
            problem = f"offsets beyond the {height}x{width} grid (max |dy|, |dx| = {far[0]:.3g}, {far[1]:.3g})"
    return problem
