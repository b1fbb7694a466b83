"""Component registry over pluggy.

Every component, built-in or third-party, is registered through one hook,
``dcfkit_register_components(registry)``, in which a plugin calls
``registry.register(SomeComponent)``. Built-ins live in :mod:`dcfkit.builtin` and are
registered exactly like plugins found through the ``dcfkit`` entry-point group. In the same
hook a plugin registers a benchmark layout with ``registry.register_dataset(name, load,
description, detect=..., aliases=...)`` (the arguments of
:func:`dcfkit.datasets.register_layout`); :mod:`dcfkit.datasets` looks it up here.
Set ``DCFKIT_DISABLE_PLUGINS=1`` to load built-ins only. Nothing happens at import time:
the registry is built on first use of :func:`get_registry`.
"""
from __future__ import annotations

import contextlib
import dataclasses
import importlib
import importlib.metadata
import inspect
import os
import signal
import types
import typing
import warnings
from typing import Any, Callable, Mapping

import pluggy

from .contracts import checked
from .errors import ConfigError, DcfkitError, DcfkitWarning, RegistryError, clip, describe_error, shown
from .params import NoParams, check_schema, closest, parse_params
from .signals import handlers_replaced

PROJECT = "dcfkit"
KINDS = ("feature", "label", "regularizer", "solver", "search", "scale")
DATASET = "dataset"  # the kind of the benchmark layouts plugins register (an Entry's cls is the Layout)
DISABLE_ENV = "DCFKIT_DISABLE_PLUGINS"
# The base classes of each kind (a regularizer's: one per role), whose ``contract`` a component
# must meet. Named, not imported: their modules import this one.
BASES = {"feature": ("dcfkit.features", "Feature"), "label": ("dcfkit.labels", "Label"),
         "regularizer": ("dcfkit.regularizers", "SpatialRegularizer", "TemporalRegularizer"),
         "solver": ("dcfkit.solvers", "Solver"), "search": ("dcfkit.search", "Search"),
         "scale": ("dcfkit.scale", "ScaleEstimator")}

hookspec = pluggy.HookspecMarker(PROJECT)
hookimpl = pluggy.HookimplMarker(PROJECT)


class HookSpecs:
    @hookspec
    def dcfkit_register_components(self, registry: "Registry") -> None:
        """Register components by calling ``registry.register(cls)`` for each, and benchmark
        layouts by calling ``registry.register_dataset(name, load, description, ...)``."""


class Component:
    """Base of all components: a ``kind``, a ``name`` and a ``Params`` schema."""

    kind: str = ""
    name: str = ""
    Params: type = NoParams

    def __init__(self, params: Any = None):
        self.params = params if params is not None else self.Params()

    def __repr__(self) -> str:
        return f"{type(self).__name__}({self.params})"


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
        return {m: self.returns.get(m) for m in (*self.required, *self.optional)}


def base_classes(kind: str) -> tuple[type, ...]:
    """The base classes of ``kind`` (:data:`BASES`)."""
    module, *names = BASES[kind]
    loaded = importlib.import_module(module)  # by name: the base modules import this one
    return tuple(getattr(loaded, n) for n in names)


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


def contract_problems(cls: type, base: type) -> list[str]:
    """What ``cls`` lacks of ``base.contract`` (an empty list: it meets it)."""
    contract: Contract = base.__dict__["contract"]
    problems = []
    for method, args in {**contract.required, **contract.optional}.items():
        if method in contract.required and getattr(cls, method, None) is getattr(base, method, None):
            problems.append(f"it does not implement {method}({', '.join(args)})")
        elif problem := _signature_problem(cls, method, args):
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
    bases = [b for b in base_classes(kind) if issubclass(cls, b)]
    if not bases:
        names = " or ".join(f"{BASES[kind][0]}.{n}" for n in BASES[kind][1:])
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


# What a plugin may raise at import or registration and be skipped for: anything it raises
# itself, an Exception or not (sys.exit(), raise KeyboardInterrupt, its own BaseException
# subclass, GeneratorExit), since one broken plugin must not end every command; an interrupt
# that a signal raised while it ran (Ctrl-C; SIGTERM, see dcfkit.tracking) goes on.
PLUGIN_FAULTS = (BaseException,)
INTERRUPTS = tuple(getattr(signal, n) for n in ("SIGINT", "SIGTERM", "SIGHUP") if hasattr(signal, n))


@contextlib.contextmanager
def signals_noted():
    """Yields a list to which every SIGINT, SIGTERM or SIGHUP arriving in the block is added
    before its handler runs. Off the main thread, where Python runs no handlers, it stays empty."""
    arrived: list[int] = []

    def noted(handler):
        if not callable(handler):  # SIG_DFL and SIG_IGN raise nothing
            return None

        def note(signum, frame):
            arrived.append(signum)
            return handler(signum, frame)
        return note

    with handlers_replaced(INTERRUPTS, noted):
        yield arrived


def _raise_if_signalled(exc: BaseException, signalled: list) -> None:
    """Re-raise what is not an Exception (an interrupt, or what the plugin made of one) when a
    signal arrived meanwhile: it is the user's, not the plugin's."""
    if signalled and not isinstance(exc, Exception):
        raise exc


class PluginWarning(DcfkitWarning, RuntimeWarning):
    """A plugin was skipped, or a name it registers withdrawn (also in ``Registry.failures``)."""


@dataclasses.dataclass(frozen=True)
class Entry:
    cls: Any  # the component class; for kind DATASET, the dcfkit.datasets.Layout
    provider: str
    distribution: str | None = None  # "name version" of the plugin's package; None for built-ins
    contract: Contract = dataclasses.field(default_factory=Contract, compare=False)  # its kind's (or role's)


class Registry:
    """Component classes by (kind, name), and plugins' benchmark layouts by name (kind
    :data:`DATASET`), with the plugin that provided each."""

    def __init__(self):
        self._entries: dict[str, dict[str, Entry]] = {k: {} for k in KINDS + (DATASET,)}
        self._ambiguous: dict[str, dict[str, list[str]]] = {k: {} for k in KINDS + (DATASET,)}
        self._provider, self._distribution = "?", None
        self.failures: list[str] = []

    def register(self, cls: type) -> type:
        """Register a component class; its ``kind`` and ``name`` must be set and new, and it must
        subclass its kind's base class and meet that class's :class:`Contract`.

        A name that two plugins both register is withdrawn: which one a config got would
        depend on the order of installation, so using it is an error naming both.
        """
        kind, name = getattr(cls, "kind", ""), getattr(cls, "name", "")
        if kind not in KINDS:
            raise RegistryError(f"{cls.__qualname__} (from {self._provider}): kind {shown(kind)} is not one of "
                                f"{', '.join(KINDS)}")
        if not name or not isinstance(name, str):
            raise RegistryError(f"{cls.__qualname__} (from {self._provider}): component has no name")
        where = f"{kind} '{name}' (from {self._provider})"
        base = base_of(cls, kind, where)
        if not dataclasses.is_dataclass(cls.Params):
            raise RegistryError(f"{where}: Params must be a dataclass")
        try:
            check_schema(cls.Params)
        except ConfigError as exc:
            raise RegistryError(f"{where}: {exc}") from None
        problems = contract_problems(cls, base)
        if problems:
            raise RegistryError(f"{where}: {'; '.join(problems)}")
        self._add(kind, name, Entry(cls, self._provider, self._distribution, base.__dict__["contract"]))
        return cls

    def register_dataset(self, name: str, load, description: str, *, detect=None, aliases=(), protocol=""):
        """Register a benchmark layout: the arguments of :func:`dcfkit.datasets.register_layout`.
        A name or alias of a layout dcfkit has (or one registered in code) is a RegistryError; one
        that two plugins register is withdrawn, as a component's name. Returns the Layout."""
        layouts = importlib.import_module("dcfkit.datasets.registry")  # named: that module imports this one
        layout = layouts.new_layout(name, load, description, detect=detect, aliases=aliases,
                                    provider=self._provider, protocol=protocol)
        for key in (layout.name,) + layout.aliases:
            self._add(DATASET, key, Entry(layout, self._provider, self._distribution))
        return layout

    def _add(self, kind: str, name: str, entry: Entry) -> None:
        """Enter ``entry`` as ``name``; a name a second plugin registers is withdrawn from both."""
        if name in self._ambiguous[kind]:
            if self._distribution is None or self._provider in self._ambiguous[kind][name]:
                raise RegistryError(f"{kind} '{name}' from {self._provider} is already registered by "
                                    f"{' and '.join(self._ambiguous[kind][name])}")
            self._ambiguous[kind][name].append(self._provider)
            return
        existing = self._entries[kind].get(name)
        if existing is not None:
            if existing.distribution is None or self._distribution is None or existing.provider == self._provider:
                raise RegistryError(f"{kind} '{name}' from {self._provider} is already registered by "
                                    f"{existing.provider}")
            del self._entries[kind][name]
            self._ambiguous[kind][name] = [existing.provider, self._provider]
            return
        self._entries[kind][name] = entry

    def names(self, kind: str) -> list[str]:
        return sorted(self._check_kind(kind))

    def datasets(self) -> list:
        """The benchmark layouts plugins registered (:class:`dcfkit.datasets.Layout`), each
        once, in registration order; one whose name is withdrawn is left out (its aliases that
        are not withdrawn still find it: :meth:`dataset`)."""
        return [e.cls for key, e in self._entries[DATASET].items() if key == e.cls.name]

    def dataset(self, name: str):
        """The layout a plugin registered as ``name`` (a name or alias; None if none did); a
        RegistryError if two plugins did."""
        if name in self._ambiguous[DATASET]:
            raise self._withdrawn(DATASET, name)
        entry = self._entries[DATASET].get(name)
        return entry.cls if entry is not None else None

    def _withdrawn(self, kind: str, name: str) -> RegistryError:
        return RegistryError(f"{kind} '{name}' is registered by more than one plugin "
                             f"({' and '.join(self._ambiguous[kind][name])}), so it is not used; "
                             f"uninstall all but one of them")

    def entry(self, kind: str, name: str) -> Entry:
        entries = self._check_kind(kind)
        if name in self._ambiguous[kind]:
            raise self._withdrawn(kind, name)
        if name not in entries:
            skipped = f"; skipped plugins: {' | '.join(self.failures)}" if self.failures else ""
            raise RegistryError(f"unknown {kind} '{clip(name)}'{closest(name, entries)}; "
                                f"registered {kind}s: {', '.join(sorted(entries)) or 'none'}{skipped}")
        return entries[name]

    def build(self, kind: str, spec: Mapping[str, Any] | str, where: str) -> Component:
        """Instantiate a component from ``{'name': ..., **params}`` (or a bare name)."""
        if isinstance(spec, str):
            spec = {"name": spec}
        if not isinstance(spec, Mapping) or not isinstance(spec.get("name"), str):  # a config's mistake
            raise ConfigError(f"{where}: expected a mapping with a 'name' key "
                              f"(one of {', '.join(self.names(kind))}), got {shown(spec)}")
        values = dict(spec)
        name = values.pop("name")
        try:
            entry = self.entry(kind, name)
        except RegistryError as exc:
            raise RegistryError(f"{where}.name: {exc}") from None
        where = f"{where} ({kind} '{name}')"
        params = parse_params(entry.cls.Params, values, where)
        check_contract_values(entry.contract, params, where)
        return checked(entry.cls(params), entry.provider, entry.contract.hooks())

    def _check_kind(self, kind: str) -> dict[str, Entry]:
        if kind not in self._entries:
            raise RegistryError(f"unknown component kind {shown(kind)}{closest(kind, KINDS)}; kinds: {', '.join(KINDS)}")
        return self._entries[kind]

    def plugin_versions(self, components) -> list[str]:
        """The plugin packages (``"name version"``, sorted) behind ``(kind, name)`` components."""
        found = {self._entries.get(kind, {}).get(name) for kind, name in components}
        return sorted({e.distribution for e in found if e is not None and e.distribution})

    def _fail(self, message: str) -> None:
        """Record and warn about a plugin problem (``dcfkit components`` lists them)."""
        self.failures.append(message)
        warnings.warn(message, PluginWarning, stacklevel=3)

    def _run_plugin(self, pm: pluggy.PluginManager, plugin: Any, provider: str,
                    distribution: str | None = None, signalled: list = ()) -> None:
        """Register one plugin's components; on failure undo them and remember why
        (``signalled``: the signals that arrived meanwhile, :func:`signals_noted`)."""
        before = {k: dict(v) for k, v in self._entries.items()}
        ambiguous = {k: {n: list(p) for n, p in v.items()} for k, v in self._ambiguous.items()}
        self._provider, self._distribution = provider, distribution
        try:
            pm.register(plugin, name=provider)
            pm.check_pending()  # catches misspelt hook names
            if not pm.get_hookcallers(plugin):
                raise RegistryError(
                    "it has no dcfkit hook: mark dcfkit_register_components with @dcfkit.registry.hookimpl"
                    + (", and let the entry point name the module that holds it (not module:function)"
                       if callable(plugin) else ""))
            others = [p for p in pm.get_plugins() if p is not plugin]
            pm.subset_hook_caller("dcfkit_register_components", remove_plugins=others)(registry=self)
        except PLUGIN_FAULTS as exc:  # a broken plugin must not break dcfkit
            _raise_if_signalled(exc, signalled)
            self._entries, self._ambiguous = before, ambiguous
            if pm.is_registered(plugin):
                pm.unregister(plugin)
            why = str(exc) if isinstance(exc, DcfkitError) else describe_error(exc)
            self._fail(f"dcfkit plugin '{provider}' failed and was skipped: {why}")
        finally:
            self._provider, self._distribution = "?", None
        for kind, clashes in self._ambiguous.items():  # names this plugin made ambiguous
            for name, providers in clashes.items():
                if providers != ambiguous[kind].get(name):
                    self._fail(f"dcfkit plugins {' and '.join(providers)} all register {kind} '{name}', "
                               f"so it is not used (uninstall all but one)")


_REGISTRY: Registry | None = None


def plugins_disabled() -> bool:
    return os.environ.get(DISABLE_ENV, "").strip().lower() not in ("", "0", "false", "no")


def get_registry() -> Registry:
    """The process-wide registry, built on first call."""
    global _REGISTRY
    if _REGISTRY is None:
        _REGISTRY = build_registry(external=not plugins_disabled())
    return _REGISTRY


def build_registry(external: bool = True) -> Registry:
    """Build a fresh registry: built-ins, then every ``dcfkit`` entry point (if ``external``)."""
    pm = pluggy.PluginManager(PROJECT)
    pm.add_hookspecs(HookSpecs)
    registry = Registry()
    with signals_noted() as signalled:
        registry._run_plugin(pm, importlib.import_module("dcfkit.builtin"), "dcfkit", signalled=signalled)
        for ep in sorted(importlib.metadata.entry_points(group=PROJECT), key=lambda e: e.name) if external else ():
            if ep.value.split(":")[0] == "dcfkit.builtin":
                continue
            provider = f"{ep.name} ({ep.value})"
            dist = getattr(ep, "dist", None)
            distribution = f"{dist.name} {dist.version}" if dist is not None else provider
            try:
                plugin = ep.load()
            except PLUGIN_FAULTS as exc:
                _raise_if_signalled(exc, signalled)
                registry._fail(f"dcfkit plugin '{provider}' could not be imported and was skipped: "
                               f"{describe_error(exc)}")
                continue
            registry._run_plugin(pm, plugin, provider, distribution, signalled)
    return registry
