"""Component registry over pluggy.

Every component, built-in or third-party, is registered through one hook,
``dcfkit_register_components(registry)``, in which a plugin calls
``registry.register(SomeComponent)``. Built-ins live in :mod:`dcfkit.builtin` and are
registered exactly like plugins found through the ``dcfkit`` entry-point group.
Set ``DCFKIT_DISABLE_PLUGINS=1`` to load built-ins only. Nothing happens at import time:
the registry is built on first use of :func:`get_registry`.
"""
from __future__ import annotations

import dataclasses
import importlib
import importlib.metadata
import os
import warnings
from typing import Any, Mapping

import pluggy

from .errors import ConfigError, DcfkitError, RegistryError, clip, describe_error, shown
from .params import NoParams, check_schema, closest, parse_params

PROJECT = "dcfkit"
KINDS = ("feature", "label", "regularizer", "solver", "search", "scale")
DISABLE_ENV = "DCFKIT_DISABLE_PLUGINS"

hookspec = pluggy.HookspecMarker(PROJECT)
hookimpl = pluggy.HookimplMarker(PROJECT)


class HookSpecs:
    @hookspec
    def dcfkit_register_components(self, registry: "Registry") -> None:
        """Register components by calling ``registry.register(cls)`` for each."""


class Component:
    """Base of all components: a ``kind``, a ``name`` and a ``Params`` schema."""

    kind: str = ""
    name: str = ""
    Params: type = NoParams

    def __init__(self, params: Any = None):
        self.params = params if params is not None else self.Params()

    def __repr__(self) -> str:
        return f"{type(self).__name__}({self.params})"


class PluginWarning(RuntimeWarning):
    """A plugin was skipped, or a name it registers withdrawn (also in ``Registry.failures``)."""


@dataclasses.dataclass(frozen=True)
class Entry:
    cls: type
    provider: str
    distribution: str | None = None  # "name version" of the plugin's package; None for built-ins


class Registry:
    """Component classes by (kind, name), with the plugin that provided each."""

    def __init__(self):
        self._entries: dict[str, dict[str, Entry]] = {k: {} for k in KINDS}
        self._ambiguous: dict[str, dict[str, list[str]]] = {k: {} for k in KINDS}
        self._provider, self._distribution = "?", None
        self.failures: list[str] = []

    def register(self, cls: type) -> type:
        """Register a component class; its ``kind`` and ``name`` must be set and new.

        A name that two plugins both register is withdrawn: which one a config got would
        depend on the order of installation, so using it is an error naming both.
        """
        kind, name = getattr(cls, "kind", ""), getattr(cls, "name", "")
        if kind not in KINDS:
            raise RegistryError(f"{cls.__qualname__} (from {self._provider}): kind {kind!r} is not one of "
                                f"{', '.join(KINDS)}")
        if not name or not isinstance(name, str):
            raise RegistryError(f"{cls.__qualname__} (from {self._provider}): component has no name")
        if not dataclasses.is_dataclass(cls.Params):
            raise RegistryError(f"{kind} '{name}' (from {self._provider}): Params must be a dataclass")
        try:
            check_schema(cls.Params)
        except ConfigError as exc:
            raise RegistryError(f"{kind} '{name}' (from {self._provider}): {exc}") from None
        if name in self._ambiguous[kind]:
            if self._distribution is None or self._provider in self._ambiguous[kind][name]:
                raise RegistryError(f"{kind} '{name}' from {self._provider} is already registered by "
                                    f"{' and '.join(self._ambiguous[kind][name])}")
            self._ambiguous[kind][name].append(self._provider)
            return cls
        existing = self._entries[kind].get(name)
        if existing is not None:
            if existing.distribution is None or self._distribution is None or existing.provider == self._provider:
                raise RegistryError(f"{kind} '{name}' from {self._provider} is already registered by "
                                    f"{existing.provider}")
            del self._entries[kind][name]
            self._ambiguous[kind][name] = [existing.provider, self._provider]
            return cls
        self._entries[kind][name] = Entry(cls, self._provider, self._distribution)
        return cls

    def names(self, kind: str) -> list[str]:
        return sorted(self._check_kind(kind))

    def entry(self, kind: str, name: str) -> Entry:
        entries = self._check_kind(kind)
        if name in self._ambiguous[kind]:
            raise RegistryError(f"{kind} '{name}' is registered by more than one plugin "
                                f"({' and '.join(self._ambiguous[kind][name])}), so it is not used; "
                                f"uninstall all but one of them")
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
            cls = self.entry(kind, name).cls
        except RegistryError as exc:
            raise RegistryError(f"{where}.name: {exc}") from None
        return cls(parse_params(cls.Params, values, f"{where} ({kind} '{name}')"))

    def _check_kind(self, kind: str) -> dict[str, Entry]:
        if kind not in self._entries:
            raise RegistryError(f"unknown component kind {kind!r}{closest(kind, KINDS)}; kinds: {', '.join(KINDS)}")
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
                    distribution: str | None = None) -> None:
        """Register one plugin's components; on failure undo them and remember why."""
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
        except (Exception, SystemExit) as exc:  # a broken plugin must not break dcfkit
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
    registry._run_plugin(pm, importlib.import_module("dcfkit.builtin"), "dcfkit")
    if external:
        for ep in sorted(importlib.metadata.entry_points(group=PROJECT), key=lambda e: e.name):
            if ep.value.split(":")[0] == "dcfkit.builtin":
                continue
            provider = f"{ep.name} ({ep.value})"
            dist = getattr(ep, "dist", None)
            distribution = f"{dist.name} {dist.version}" if dist is not None else provider
            try:
                plugin = ep.load()
            except (Exception, SystemExit) as exc:
                registry._fail(f"dcfkit plugin '{provider}' could not be imported and was skipped: "
                               f"{describe_error(exc)}")
                continue
            registry._run_plugin(pm, plugin, provider, distribution)
    return registry
