"""The component registry: built-ins, plugins, duplicates and broken plugins."""
import importlib.metadata
import sys
import types
import warnings

import pytest

from dcfkit import registry as reg
from dcfkit.errors import RegistryError
from dcfkit.labels import Label


class FakeEntryPoint:
    def __init__(self, name, module):
        self.name, self.value, self._module = name, f"{module}", module

    def load(self):
        __import__(self._module)
        return sys.modules[self._module]


def install_plugin(monkeypatch, module_name, source):
    """Make ``module_name`` importable with ``source`` and expose it as a dcfkit entry point."""
    module = types.ModuleType(module_name)
    try:
        exec(source, module.__dict__)
    except RuntimeError:
        pass
    else:
        monkeypatch.setitem(sys.modules, module_name, module)
    return FakeEntryPoint(module_name.split(".")[-1], module_name)


def with_entry_points(monkeypatch, eps):
    monkeypatch.setattr(importlib.metadata, "entry_points",
                        lambda group=None: [e for e in eps] if group == "dcfkit" else [])


PLUGIN = '''
import dataclasses
from dcfkit.registry import hookimpl
from dcfkit.labels import Label
from dcfkit.params import param

class Flat(Label):
    """A constant label (for tests)."""
    name = "flat"
    @dataclasses.dataclass(frozen=True)
    class Params:
        level: float = param(0.5, "constant value")
    def make(self, g, detection):
        return g * 0 + self.params.level, None

@hookimpl
def dcfkit_register_components(registry):
    registry.register(Flat)
'''


def test_builtins_are_registered_with_their_provider():
    r = reg.build_registry(external=False)
    assert {"gray", "fhog", "colornames"} <= set(r.names("feature"))
    assert r.names("label") == ["distractor_repressed", "gaussian"]
    assert {"admm_strcf", "admm_bacf"} <= set(r.names("solver"))
    assert r.entry("label", "gaussian").provider == "dcfkit"


def test_plugin_component_is_found_and_built(monkeypatch):
    with_entry_points(monkeypatch, [install_plugin(monkeypatch, "dcfkit_test_flat", PLUGIN)])
    r = reg.build_registry()
    assert "flat" in r.names("label")
    assert r.entry("label", "flat").provider.startswith("dcfkit_test_flat")
    label = r.build("label", {"name": "flat", "level": 2}, "test: label")
    assert label.params.level == 2.0


def test_duplicate_name_is_refused_and_the_rest_still_works(monkeypatch):
    dup = PLUGIN.replace('name = "flat"', 'name = "gaussian"')
    with_entry_points(monkeypatch, [install_plugin(monkeypatch, "dcfkit_test_dup", dup)])
    with pytest.warns(RuntimeWarning, match=r"dcfkit_test_dup.*label 'gaussian'.*already registered by dcfkit"):
        r = reg.build_registry()
    assert r.entry("label", "gaussian").provider == "dcfkit"
    assert any("dcfkit_test_dup" in f for f in r.failures)


def test_plugin_raising_on_import_is_contained(monkeypatch):
    broken = install_plugin(monkeypatch, "dcfkit_test_broken", "raise RuntimeError('plugin bug at import')")
    monkeypatch.delitem(sys.modules, "dcfkit_test_broken", raising=False)  # importing it now fails
    good = install_plugin(monkeypatch, "dcfkit_test_good", PLUGIN)
    with_entry_points(monkeypatch, [broken, good])
    with pytest.warns(RuntimeWarning, match=r"dcfkit_test_broken.*could not be imported"):
        r = reg.build_registry()
    assert "flat" in r.names("label") and "gaussian" in r.names("label")


def test_misspelt_hook_is_reported(monkeypatch):
    bad = PLUGIN.replace("def dcfkit_register_components", "def dcfkit_register_component")
    with_entry_points(monkeypatch, [install_plugin(monkeypatch, "dcfkit_test_typo", bad)])
    with pytest.warns(RuntimeWarning, match=r"dcfkit_test_typo.*dcfkit_register_component"):
        r = reg.build_registry()
    assert "flat" not in r.names("label")
    with pytest.raises(RegistryError, match=r"unknown label 'flat'.*skipped plugins: .*dcfkit_test_typo"):
        r.entry("label", "flat")


def test_components_command_fails_when_a_plugin_was_skipped(monkeypatch, capsys):
    from dcfkit import cli

    bad = PLUGIN.replace("def dcfkit_register_components", "def dcfkit_register_component")
    with_entry_points(monkeypatch, [install_plugin(monkeypatch, "dcfkit_test_typo2", bad)])
    monkeypatch.setattr(reg, "_REGISTRY", None)
    with warnings.catch_warnings(record=True) as shown:
        warnings.simplefilter("always")
        assert cli.main(["components", "--kind", "label"]) == 1
    assert not [w for w in shown if "dcfkit plugin" in str(w.message)]  # listed by the command instead
    err = capsys.readouterr().err
    assert err.count("warning: dcfkit plugin 'dcfkit_test_typo2") == 1 and "RuntimeWarning" not in err
    monkeypatch.setattr(reg, "_REGISTRY", None)


def test_other_commands_show_a_skipped_plugin_as_one_line(monkeypatch, capsys, tmp_path):
    from dcfkit import cli

    bad = PLUGIN.replace("def dcfkit_register_components", "def dcfkit_register_component")
    with_entry_points(monkeypatch, [install_plugin(monkeypatch, "dcfkit_test_typo3", bad)])
    monkeypatch.setattr(reg, "_REGISTRY", None)
    with warnings.catch_warnings():
        warnings.simplefilter("always")
        assert cli.main(["track", "strcf", "--frames", str(tmp_path), "--box", "1,1,5,5"]) == 2  # no frames
    err = capsys.readouterr().err
    assert err.count("warning: dcfkit plugin 'dcfkit_test_typo3") == 1 and "RuntimeWarning" not in err
    monkeypatch.setattr(reg, "_REGISTRY", None)


def test_environment_variable_disables_plugins(monkeypatch):
    with_entry_points(monkeypatch, [install_plugin(monkeypatch, "dcfkit_test_flat2", PLUGIN)])
    monkeypatch.setenv(reg.DISABLE_ENV, "1")
    monkeypatch.setattr(reg, "_REGISTRY", None)
    assert "flat" not in reg.get_registry().names("label")
    monkeypatch.setattr(reg, "_REGISTRY", None)


def test_bad_registrations_are_errors():
    r = reg.Registry()

    class NoName(Label):
        pass

    with pytest.raises(RegistryError, match="has no name"):
        r.register(NoName)

    class Wrong(Label):
        kind = "colour"
        name = "x"

    with pytest.raises(RegistryError, match="kind 'colour' is not one of"):
        r.register(Wrong)
    with pytest.raises(RegistryError, match=r"unknown component kind 'labels'.*did you mean 'label'"):
        r.names("labels")
