"""The component registry, over pluggy: it knows kinds only as their base classes declare them.

Every plugin, dcfkit's own included, is a module named by an entry point of the ``dcfkit``
group whose hook ``dcfkit_register_components(registry)`` calls ``registry.register(cls)``
and ``registry.register_dataset(...)``. dcfkit's entry points load first; set
``DCFKIT_DISABLE_PLUGINS=1`` to load only them. The registry is built on first use of
:func:`get_registry`, never at import.
"""
from __future__ import annotations

import contextlib
import dataclasses
import importlib.metadata
import os
import warnings
from typing import Any, Callable, Mapping

import pluggy

from dcfkit.components.base import Component, Contract, base_of, check_contract_values, contract_problems, kinds
from dcfkit.contracts import checked
from dcfkit.errors import ConfigError, DcfkitError, DcfkitWarning, RegistryError, clip, describe_error, shown
from dcfkit.params import check_schema, closest, parse_params
from dcfkit.signals import INTERRUPTS, handlers_replaced

PROJECT = "dcfkit"
DATASET = "dataset"  # the kind of the benchmark layouts plugins register (an Entry's cls is the Layout)
DISABLE_ENV = "DCFKIT_DISABLE_PLUGINS"
__all__ = ["Component", "Contract", "PluginWarning", "Registry", "build_registry", "get_registry", "hookimpl"]

hookspec = pluggy.HookspecMarker(PROJECT)
hookimpl = pluggy.HookimplMarker(PROJECT)


class HookSpecs:
    @hookspec
    def dcfkit_register_components(self, registry: "Registry") -> None:
        """Register components by calling ``registry.register(cls)`` for each, and benchmark
        layouts by calling ``registry.register_dataset(name, load, description, ...)``."""


# What a plugin may raise at import or registration and be skipped for: anything it raises
# itself, an Exception or not (sys.exit(), raise KeyboardInterrupt, its own BaseException
# subclass, GeneratorExit), since one broken plugin must not end every command; an interrupt
# that a signal raised while it ran (Ctrl-C; SIGTERM, see dcfkit.signals) goes on.
PLUGIN_FAULTS = (BaseException,)


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

    def __init__(self, make_layout: Callable | None = None):
        """``make_layout``: how :meth:`register_dataset` makes a layout
        (:func:`dcfkit.datasets.layout.new_layout`); dcfkit's own plugin sets it when not given."""
        self._entries: dict[str, dict[str, Entry]] = {DATASET: {}}  # then each kind, as first registered
        self._ambiguous: dict[str, dict[str, list[str]]] = {DATASET: {}}
        self._make_layout = make_layout
        self._provider, self._distribution = "?", None
        self.failures: list[str] = []

    def register(self, cls: type) -> type:
        """Register a component class; its ``kind`` and ``name`` must be set and new, and it must
        subclass its kind's base class and meet that class's :class:`Contract`.

        A name that two plugins both register is withdrawn: which one a config got would
        depend on the order of installation, so using it is an error naming both.
        """
        kind, name = getattr(cls, "kind", ""), getattr(cls, "name", "")
        if kind not in kinds():
            raise RegistryError(f"{cls.__qualname__} (from {self._provider}): kind {shown(kind)} is not one of "
                                f"{', '.join(kinds())}")
        self._entries.setdefault(kind, {})
        self._ambiguous.setdefault(kind, {})
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
        if self._make_layout is None:
            raise RegistryError(f"{self._provider}: this registry takes no benchmark layouts: use "
                                f"build_registry(), or Registry(make_layout=dcfkit.datasets.layout.new_layout)")
        layout = self._make_layout(name, load, description, detect=detect, aliases=aliases,
                                   provider=self._provider, protocol=protocol)
        for key in (layout.name,) + layout.aliases:
            self._add(DATASET, key, Entry(layout, self._provider, self._distribution))
        return layout

    def accept_layouts(self, make_layout: Callable) -> None:
        """Make benchmark layouts with ``make_layout`` (the arguments of :meth:`register_dataset`
        and ``provider``): dcfkit's own plugin calls it, so that the registry imports no dataset code."""
        if self._distribution is not None:
            raise RegistryError(f"{self._provider}: only dcfkit's own plugin says how layouts are made")
        self._make_layout = self._make_layout or make_layout

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

    def kinds(self) -> list[str]:
        """The component kinds, in the order dcfkit's own plugin registers them."""
        return [k for k in self._entries if k != DATASET]

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

    def resolve(self, kind: str, spec: Mapping[str, Any] | str, where: str) -> tuple[Entry, Any]:
        """The entry and checked ``Params`` of ``{'name': ..., **params}`` (or a bare name),
        without building the component; a ConfigError naming ``where`` and the key otherwise."""
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
        return entry, params

    def build(self, kind: str, spec: Mapping[str, Any] | str, where: str) -> Component:
        """The component of ``spec`` (:meth:`resolve`), its hooks checked on every call."""
        entry, params = self.resolve(kind, spec, where)
        return checked(entry.cls(params), entry.provider, entry.contract.hooks())

    def _check_kind(self, kind: str) -> dict[str, Entry]:
        if kind not in self._entries and kind not in kinds():
            known = kinds()
            raise RegistryError(f"unknown component kind {shown(kind)}{closest(kind, known)}; kinds: {', '.join(known)}")
        self._ambiguous.setdefault(kind, {})
        return self._entries.setdefault(kind, {})

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


def _own(ep) -> bool:
    dist = getattr(ep, "dist", None)
    return dist is not None and dist.name.lower().replace("_", "-") == PROJECT


def plugin_entry_points(external: bool = True) -> tuple[list, list]:
    """(dcfkit's own entry points, the others' if ``external``), each sorted by name. No entry
    point of dcfkit's own is a RegistryError: its components would be missing."""
    found = sorted(importlib.metadata.entry_points(group=PROJECT), key=lambda e: e.name)
    own = [ep for ep in found if _own(ep)]
    if not own:
        raise RegistryError("dcfkit's own plugin (entry point 'builtin' of group 'dcfkit') is not installed, "
                            "so no component is known: install dcfkit (pip install -e .), not just its folder")
    return own, [ep for ep in found if not _own(ep)] if external else []


def build_registry(external: bool = True) -> Registry:
    """Build a fresh registry: dcfkit's own plugin, then every other ``dcfkit`` entry point (if
    ``external``), each through the same hook."""
    pm = pluggy.PluginManager(PROJECT)
    pm.add_hookspecs(HookSpecs)
    registry = Registry()
    own, others = plugin_entry_points(external)
    with signals_noted() as signalled:
        for ep, ours in [(ep, True) for ep in own] + [(ep, False) for ep in others]:
            provider = PROJECT if ours else f"{ep.name} ({ep.value})"
            dist = getattr(ep, "dist", None)
            distribution = None if ours else f"{dist.name} {dist.version}" if dist is not None else provider
            try:
                plugin = ep.load()
            except PLUGIN_FAULTS as exc:
                _raise_if_signalled(exc, signalled)
                registry._fail(f"dcfkit plugin '{provider}' could not be imported and was skipped: "
                               f"{describe_error(exc)}")
                continue
            registry._run_plugin(pm, plugin, provider, distribution, signalled)
    return registry
