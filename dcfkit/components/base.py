"""What every component is: a ``kind``, a ``name``, a ``Params`` schema, and the
:class:`Contract` of its kind, which the kind's base class declares
(``class Label(Component, declares="label")``). The registry checks classes against it."""
from __future__ import annotations

import contextlib
import dataclasses
import inspect
import types
import typing
from typing import Any, Callable, Mapping

import numpy as np

from dcfkit.errors import ConfigError, RegistryError, shown
from dcfkit.params import NoParams

_BASES: dict[str, list[type]] = {}  # kind -> its base classes (a regularizer's: one per role), as declared


def kinds() -> tuple[str, ...]:
    """The kinds declared so far, in the order their base classes were defined."""
    return tuple(_BASES)


def running_average(model: np.ndarray | None, sample: np.ndarray, rate: float, dtype=None) -> np.ndarray:
    """A model kept across frames: ``sample`` itself on the first frame (``model`` None), else
    (1 - η) model + η sample (BACF's and ARCF's sample model, KCF's ``interp_factor``, DSST's
    Eq. 3, CSR-DCF's histograms and channel weights, ECO's scale model); cast to ``dtype`` if
    given. Every kind's components keep their models with it."""
    if model is None:
        new = np.array(sample, copy=True)
    else:
        new = (1 - rate) * model + rate * sample
    return new if dtype is None else new.astype(dtype, copy=False)


@dataclasses.dataclass(frozen=True)
class Target:
    """The geometry of a new target, given to every component at each ``init``
    (:meth:`Component.start`). Sizes are ``(h, w)``; cells are feature cells of the training
    grid, whose middle (the target's, and the label's peak) is cell ``(0, 0)`` in the circular
    layout every map uses (docs/plugins.md, "Where the target's middle lies").

    ``image_size``: frame 1's ``(H, W)`` pixels; ``filter_size``: the ``(H, W)`` cells of the
    filter, the label and the response; ``target_cells``: the target in cells; ``cell_size``:
    pixels per cell (the config's, or smaller for a small target); ``scale``: pixels of the
    image per pixel of the resampled patch; ``sigma``: the base label's σ in cells (Eq. 1);
    ``template``: CSR-DCF's square template's side in image pixels (``tracker.search_area_shape:
    padded_square``), else None."""

    image_size: tuple[int, int]
    filter_size: tuple[int, int]
    target_cells: tuple[float, float]
    cell_size: int
    scale: float
    sigma: float
    template: float | None = None


class Component:
    """Base of all components: a ``kind``, a ``name`` and a ``Params`` schema."""

    kind: str = ""
    name: str = ""
    Params: type = NoParams

    def __init_subclass__(cls, declares: str | None = None, **kwargs):
        """``class Label(Component, declares="label")`` makes ``Label`` the base class of a kind:
        it sets ``kind`` and must hold the kind's :class:`Contract` as ``contract``."""
        super().__init_subclass__(**kwargs)
        if declares is None:
            return
        if not isinstance(cls.__dict__.get("contract"), Contract):
            raise TypeError(f"{cls.__qualname__} declares kind {declares!r} without a Contract as 'contract'")
        cls.kind = declares
        _BASES.setdefault(declares, []).append(cls)

    def __init__(self, params: Any = None):
        self.params = params if params is not None else self.Params()

    def __repr__(self) -> str:
        return f"{type(self).__name__}({self.params})"

    def start(self, target: Target) -> None:
        """Called at every ``init``, after ``reset``, with the new target's geometry (a label that
        needs σ or the cell size reads them here). The built-ins need nothing from it."""


@dataclasses.dataclass(frozen=True)
class Contract:
    """What the tracker needs of one kind of component (or regularizer role): set as ``contract``
    on the kind's base class, checked by :meth:`Registry.register` (docs/plugins.md, section 5).

    ``required``: methods the component must implement, name -> the arguments the tracker
    passes after ``self``; ``optional``: the same for methods the base class implements.
    ``params``: ``Params`` fields the tracker reads, name -> (type, lowest, highest): the field
    must exist with that annotation, and a value outside the range is a ConfigError whenever
    the component is built (the arithmetic that receives it needs the range).
    ``returns``: method -> the check of what it returns (:mod:`dcfkit.contracts`), run on every
    call of a built component.
    """

    required: Mapping[str, tuple[str, ...]] = dataclasses.field(default_factory=dict)
    optional: Mapping[str, tuple[str, ...]] = dataclasses.field(default_factory=dict)
    params: Mapping[str, tuple[type, float, float]] = dataclasses.field(default_factory=dict)
    returns: Mapping[str, Callable] = dataclasses.field(default_factory=dict)

    def hooks(self) -> dict[str, Callable | None]:
        """Every method the tracker calls -> its return check (None: none)."""
        return {m: self.returns.get(m) for m in (*self.required, *self.optional, *EVERY_KIND)}


#: what the tracker calls on a component of any kind, beyond its kind's contract
EVERY_KIND: Mapping[str, tuple[str, ...]] = {"start": ("target",)}


def _as_called(cls: type, method: str) -> tuple[Any, bool]:
    """(what ``instance.method`` is, whether it receives the instance) for an instance of
    ``cls``: the class attribute bound as Python binds it, so that a function, a
    ``functools.lru_cache`` or ``partialmethod`` and a ``functools.wraps`` wrapper receive the
    instance, a static method or a callable object does not. The instance is made without
    running ``__init__``; TypeError if it cannot be (an abstract class)."""
    raw = inspect.getattr_static(cls, method)
    get = getattr(type(raw), "__get__", None)
    if get is None:  # a callable object in the class: called with the tracker's arguments alone
        return raw, False
    instance = object.__new__(cls)
    called = get(raw, instance, cls)
    return called, getattr(called, "__self__", None) is instance


def _signature_problem(cls: type, method: str, args: tuple[str, ...]) -> str | None:
    """Why ``cls().method(*args)`` cannot be called as the tracker calls it, or None."""
    found = getattr(cls, method, None)
    if not callable(found):
        return f"{method} is {'missing' if found is None else 'not a method'}"
    try:
        called, takes_self = _as_called(cls, method)
        signature = inspect.signature(called)
    except (TypeError, ValueError):  # no signature (a builtin), or no instance without __init__: on trust
        return None
    try:
        signature.bind(*([None] * len(args)))
    except TypeError:
        with_self = False  # a method is shown as written, self included
        if isinstance(called, types.MethodType) and takes_self:
            with contextlib.suppress(TypeError, ValueError):
                signature, with_self = inspect.signature(called.__func__), True
        return (f"{method}{signature} cannot be called as {method}({', '.join(('self',) * with_self + args)}) "
                f"(the tracker passes {len(args)} argument{'s' * (len(args) != 1)})")
    return None


def _body_problem(cls: type, method: str) -> str | None:
    """Why ``cls``'s ``method`` would not run when called, or None: a generator or async
    function returns a generator or coroutine without running a line of its body."""
    try:
        called, _ = _as_called(cls, method)
    except (TypeError, AttributeError):  # no instance without __init__, or missing: said elsewhere
        return None
    for test, kind in ((inspect.isgeneratorfunction, "a generator function (it yields)"),
                       (inspect.iscoroutinefunction, "an async function"),
                       (inspect.isasyncgenfunction, "an async generator function")):
        if test(called):
            return (f"{method}() is {kind}: the tracker's call would return a "
                    f"{'coroutine' if kind == 'an async function' else 'generator'} and run none of it; "
                    f"make it a plain method")
    return None


def contract_problems(cls: type, base: type) -> list[str]:
    """What ``cls`` lacks of ``base.contract`` (an empty list: it meets it)."""
    contract: Contract = base.__dict__["contract"]
    problems = []
    for method, args in {**contract.required, **contract.optional, **EVERY_KIND}.items():
        if method in contract.required and getattr(cls, method, None) is getattr(base, method, None):
            problems.append(f"it does not implement {method}({', '.join(args)})")
        elif problem := _signature_problem(cls, method, args) or _body_problem(cls, method):
            problems.append(problem)
    hints = typing.get_type_hints(cls.Params)
    for field, (kind, lowest, highest) in contract.params.items():
        if hints.get(field) is not kind:
            problems.append(f"its Params has no {kind.__name__} field '{field}' (the tracker reads "
                            f"params.{field}, in [{lowest:g}, {highest:g}])")
        elif not lowest <= (default := getattr(cls.Params(), field)) <= highest:
            problems.append(f"its default {field}={shown(default)} is outside [{lowest:g}, {highest:g}]")
    return problems


def base_of(cls: type, kind: str, where: str) -> type:
    """The base class of ``kind`` that ``cls`` subclasses (a RegistryError if none)."""
    bases = [b for b in _BASES.get(kind, ()) if issubclass(cls, b)]
    if not bases:
        names = " or ".join(f"{b.__module__.removesuffix('.base')}.{b.__qualname__}" for b in _BASES.get(kind, ()))
        raise RegistryError(f"{where}: a {kind} must subclass {names}")
    base = bases[-1]  # the most specific, should a class subclass both roles' bases
    if hasattr(base, "role") and getattr(cls, "role", None) != base.role:
        raise RegistryError(f"{where}: role {shown(getattr(cls, 'role', None))} is not its base class "
                            f"{base.__name__}'s ({base.role!r})")
    return base


def check_contract_values(contract: Contract, params: Any, where: str) -> None:
    """A ConfigError if a parameter the tracker reads is outside its contract's range."""
    for field, (_, lowest, highest) in contract.params.items():
        value = getattr(params, field)
        if not lowest <= value <= highest:
            raise ConfigError(f"{where}.{field}: {shown(value)} is outside [{lowest:g}, {highest:g}]")
