"""The component registry: built-ins, plugins, duplicates and broken plugins."""
import dataclasses
import importlib.metadata
import sys
import types
import warnings

import numpy as np
import pytest

from dcfkit import registry as reg
from dcfkit.components.labels.base import Label
from dcfkit.errors import ConfigError, RegistryError
from dcfkit.params import fields, param, parse_params


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


OWN_ENTRY_POINTS = reg.plugin_entry_points(external=False)[0]  # dcfkit's own, loaded as a plugin's


def with_entry_points(monkeypatch, eps):
    """The installed ``dcfkit`` entry points are dcfkit's own and ``eps``."""
    monkeypatch.setattr(importlib.metadata, "entry_points",
                        lambda group=None: OWN_ENTRY_POINTS + list(eps) if group == "dcfkit" else [])


PLUGIN = '''
import dataclasses
import numpy as np
from dcfkit.registry import hookimpl
from dcfkit.components.labels import Label
from dcfkit.params import param

class Flat(Label):
    """A constant label (for tests)."""
    name = "flat"
    @dataclasses.dataclass(frozen=True)
    class Params:
        level: float = param(0.5, "constant value")
    def make(self, g, detection):
        return g * 0 + self.params.level, np.zeros((0, 2), int)

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


@pytest.mark.parametrize("plugins, shown", [
    ({"dcfkit_test_typo3": PLUGIN.replace("def dcfkit_register_components", "def dcfkit_register_component")},
     "warning: dcfkit plugin 'dcfkit_test_typo3"),
    ({"dcfkit_test_c1": PLUGIN, "dcfkit_test_c2": PLUGIN}, "warning: dcfkit plugins dcfkit_test_c1"),  # withdrawn
])
def test_other_commands_show_a_plugin_problem_as_one_line(monkeypatch, capsys, tmp_path, plugins, shown):
    from dcfkit import cli

    with_entry_points(monkeypatch, [install_plugin(monkeypatch, name, source) for name, source in plugins.items()])
    monkeypatch.setattr(reg, "_REGISTRY", None)
    with warnings.catch_warnings():
        warnings.simplefilter("always")
        assert cli.main(["track", "strcf", "--frames", str(tmp_path), "--box", "1,1,5,5"]) == 2  # no frames
    err = capsys.readouterr().err
    assert err.count(shown) == 1 and "RuntimeWarning" not in err
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


def test_a_name_two_plugins_register_is_withdrawn_and_their_other_components_stay(monkeypatch):
    # which plugin won used to depend on entry-point order; results of either could be mixed up
    both = PLUGIN.replace("registry.register(Flat)", "registry.register(Flat)\n    registry.register(Other)")
    first = both.replace("@hookimpl", 'class Other(Flat):\n    name = "other_a"\n\n@hookimpl')
    second = both.replace("@hookimpl", 'class Other(Flat):\n    name = "other_b"\n\n@hookimpl')
    with_entry_points(monkeypatch, [install_plugin(monkeypatch, "dcfkit_test_a", first),
                                    install_plugin(monkeypatch, "dcfkit_test_b", second)])
    with pytest.warns(RuntimeWarning, match=r"dcfkit_test_a.*and dcfkit_test_b.*all register label 'flat'"):
        r = reg.build_registry()
    assert {"other_a", "other_b"} <= set(r.names("label")) and "flat" not in r.names("label")
    with pytest.raises(RegistryError, match=r"label 'flat' is registered by more than one plugin "
                                            r"\(dcfkit_test_a .* and dcfkit_test_b .*\)"):
        r.build("label", "flat", "test: label")


@pytest.mark.parametrize("source, message", [
    (PLUGIN.replace("@hookimpl\n", ""), r"it has no dcfkit hook: mark dcfkit_register_components with "
                                        r"@dcfkit.registry.hookimpl$"),
    ("import sys\nsys.exit(2)", r"could not be imported and was skipped: SystemExit: 2 \(at "),
    ("import json\njson.loads('{')", r"could not be imported and was skipped: JSONDecodeError: .* \(at .*:\d+\)"),
    (PLUGIN.replace("registry.register(Flat)", "{}['label_class']"),
     r"failed and was skipped: KeyError: 'label_class' \(at <string>:\d+\)"),
    (PLUGIN.replace("registry.register(Flat)", "registry.register(Flat)\n    registry.register(Flat)"),
     r"failed and was skipped: label 'flat' from dcfkit_test_problem .* already registered by dcfkit_test_problem"),
    (PLUGIN.replace("registry.register(Flat)", "registry.accept_layouts(lambda *a, **k: None)"),
     r"failed and was skipped: dcfkit_test_problem .*: only dcfkit's own plugin says how layouts are made"),
])
def test_plugin_problems_say_what_and_where(monkeypatch, source, message):
    ep = install_plugin(monkeypatch, "dcfkit_test_problem", "")

    def load():  # import the source now, as an entry point does
        module = types.ModuleType("dcfkit_test_problem")
        exec(compile(source, "<string>", "exec"), module.__dict__)
        return module
    ep.load = load
    with_entry_points(monkeypatch, [ep])
    with pytest.warns(RuntimeWarning) as shown:
        r = reg.build_registry()
    assert any(__import__("re").search(message, str(w.message)) for w in shown), [str(w.message) for w in shown]
    assert "flat" not in r.names("label") and "gaussian" in r.names("label")


def test_an_entry_point_naming_the_hook_function_gets_a_hint(monkeypatch):
    ep = install_plugin(monkeypatch, "dcfkit_test_function", PLUGIN)
    ep.value, ep.load = "dcfkit_test_function:dcfkit_register_components", \
        lambda: sys.modules["dcfkit_test_function"].dcfkit_register_components
    with_entry_points(monkeypatch, [ep])
    with pytest.warns(RuntimeWarning, match=r"no dcfkit hook.*name the module that holds it \(not module:function\)"):
        r = reg.build_registry()
    assert "flat" not in r.names("label")


@pytest.mark.parametrize("field, message", [
    ("level: float = 0.5", None),
    ("level: float = dataclasses.field(default=0.5)", None),
    ("level: float = dataclasses.field(default_factory=float)", r"parameter 'level' has no default"),
    ("level: int = param(2.5, 'a count')", r"default Params.level: expected an integer, got 2.5"),
    ("level: np.float32 = param(0.5, 'x')", r"parameter 'level': annotation .*float32.* is not supported"),
    ("level: 'float | None' = param(None, 'x')", None),
    ("level: 'tuple[float, ...]' = param((1.0, 2.0), 'x')", None),
    ("level: tuple = param((1, 'a'), 'x')", None),
    ("level: 'int | float' = param(1, 'x')", r"parameter 'level': annotation .* is not supported"),
    ("level: float = param(0.5, 'x', gt=0, le=1)", None),
    ("level: 'int | None' = param(None, 'x', ge=1)", None),
    ("level: float = param(1.5, 'x', gt=0, le=1)", r"default Params: level must be in \(0, 1\], got 1.5"),
    ("level: str = param('a', 'x', ge=0)", r"parameter 'level': bounds \(ge, gt, le, lt\) need an int or float"),
])
def test_params_schemas_are_checked_when_the_component_registers(field, message):
    namespace = {"dataclasses": dataclasses, "np": np, "param": param}
    exec(f"@dataclasses.dataclass(frozen=True)\nclass Params:\n    {field}\n", namespace)

    class Checked(Label):
        name = "checked"
        Params = namespace["Params"]

        def make(self, g, detection):
            return g, np.zeros((0, 2), int)

    r = reg.Registry()
    if message is None:
        r.register(Checked)
        assert r.entry("label", "checked").cls is Checked
    else:
        with pytest.raises(RegistryError, match=r"label 'checked' \(from \?\): " + message):
            r.register(Checked)


@pytest.mark.parametrize("limits, inside, outside, message", [
    ({"ge": 1, "le": 10000}, [1, 10000], [0, 10001, -1e300], r"x: n must be in \[1, 10000\], got "),
    ({"gt": 0}, [5e-324, 1e300], [0, -0.0, -1e-300], r"x: n must be > 0, got "),
    ({"gt": 0, "lt": 1}, [0.5], [0, 1], r"x: n must be in \(0, 1\), got "),
    ({"le": 10}, [-1e300, 10], [10.5], r"x: n must be <= 10, got "),
])
def test_declared_bounds_are_checked_and_described(limits, inside, outside, message):
    @dataclasses.dataclass(frozen=True)
    class Params:
        n: float = param(0.5 if "lt" in limits else 1, "a number", **limits)

    for value in inside:
        assert parse_params(Params, {"n": value}, "x").n == value
    for value in outside:
        with pytest.raises(ConfigError, match=message):
            parse_params(Params, {"n": value}, "x")
    assert fields(Params)[0]["bounds"] == message.split("must be ")[1].split(", got")[0].removeprefix("in ").replace(
        "\\", "")


@pytest.mark.parametrize("limits", [{"ge": 0, "gt": 0}, {"le": 1, "lt": 1}, {"ge": 2, "le": 1}, {"ge": "0"},
                                    {"gt": float("nan")}, {"le": True}])
def test_impossible_bounds_are_a_type_error_where_the_field_is_declared(limits):
    with pytest.raises(TypeError, match="param limits"):
        param(1.0, "a number", **limits)


def test_union_and_fixed_tuple_annotations_are_checked():
    @dataclasses.dataclass(frozen=True)
    class Params:
        sigma: float | None = param(None, "optional width")
        size: tuple[int, int] = param((3, 4), "rows, columns")

        def validate(self):
            assert self.size[0] > 0

    assert parse_params(Params, {"sigma": "1e-3"}, "x").sigma == 1e-3
    assert parse_params(Params, {"sigma": None}, "x").sigma is None
    with pytest.raises(ConfigError, match=r"x.sigma: expected a number, got 'abc'"):
        parse_params(Params, {"sigma": "abc"}, "x")
    with pytest.raises(ConfigError, match=r"x.size: expected a list of 2 values, got \[1, 2, 3\]"):
        parse_params(Params, {"size": [1, 2, 3]}, "x")
    with pytest.raises(ConfigError, match=r"x.size\[1\]: expected an integer, got 'a'"):
        parse_params(Params, {"size": [1, "a"]}, "x")
    with pytest.raises(ConfigError, match=r"x: invalid parameters \(.*Params.validate\(\) raised AssertionError.*\)"):
        parse_params(Params, {"size": [0, 1]}, "x")


def test_result_hashes_change_with_the_version_of_a_plugin_the_config_uses(monkeypatch):
    from dcfkit.config import load_config
    from dcfkit.errors import DcfkitError
    from dcfkit.store.provenance import dcfkit_version, run_key
    from dcfkit.running.runner import RunTask, check_worker

    def registry_with(version):
        ep = install_plugin(monkeypatch, "dcfkit_test_versioned", PLUGIN)
        ep.dist = types.SimpleNamespace(name="dcfkit-test-versioned", version=version)
        with_entry_points(monkeypatch, [ep])
        monkeypatch.setattr(reg, "_REGISTRY", reg.build_registry())

    monkeypatch.setattr(reg, "_REGISTRY", reg.build_registry(external=False))
    plain = run_key(load_config("strcf"))
    registry_with("0.1.0")
    flat = load_config("strcf", {"label.name": "flat"})
    assert run_key(load_config("strcf")) == plain  # built-ins only: unchanged by installed plugins
    assert reg.get_registry().plugin_versions([("label", "flat")]) == ["dcfkit-test-versioned 0.1.0"]
    old_key = run_key(flat)
    registry_with("0.2.0")
    assert run_key(flat) != old_key
    monkeypatch.setattr("dcfkit.running.runner._worker_ready", True)  # no worker set-up in the test process
    with pytest.raises(DcfkitError, match=r"worker's dcfkit code \(\w+\) or plugins \(dcfkit-test-versioned 0.2.0\) "
                       r"are not the client's"):
        check_worker(RunTask(flat, None, "unused", old_key), dcfkit_version())
    monkeypatch.setattr(reg, "_REGISTRY", None)


def test_an_ambiguous_name_survives_a_plugin_failing_half_way_and_refuses_a_second_registration(monkeypatch):
    fails = PLUGIN.replace("registry.register(Flat)", "registry.register(Flat)\n    raise RuntimeError('later')")
    twice = PLUGIN.replace("registry.register(Flat)", "registry.register(Flat)\n    registry.register(Flat)")
    with_entry_points(monkeypatch, [install_plugin(monkeypatch, "dcfkit_test_a1", PLUGIN),
                                    install_plugin(monkeypatch, "dcfkit_test_a2", PLUGIN),
                                    install_plugin(monkeypatch, "dcfkit_test_b1", fails),
                                    install_plugin(monkeypatch, "dcfkit_test_b2", twice)])
    with pytest.warns(RuntimeWarning) as shown:
        r = reg.build_registry()
    messages = [str(w.message) for w in shown]
    assert any("dcfkit_test_b1" in m and "RuntimeError: later" in m for m in messages)
    assert any("dcfkit_test_b2" in m and "already registered by dcfkit_test_a1 (dcfkit_test_a1) and "
               "dcfkit_test_a2 (dcfkit_test_a2) and dcfkit_test_b2" in m for m in messages)
    with pytest.raises(RegistryError, match=r"registered by more than one plugin \(dcfkit_test_a1 \(dcfkit_test_a1\) "
                                            r"and dcfkit_test_a2 \(dcfkit_test_a2\)\)"):  # the failed ones undone
        r.entry("label", "flat")
    with pytest.raises(RegistryError, match="already registered"):  # outside plugin loading
        r.register(type("Flat", (Label,), {"name": "flat", "make": lambda self, g, detection: (g, None)}))


def _reordered(value):
    """``value`` with the keys of every mapping in it in reverse order."""
    if isinstance(value, dict):
        return {k: _reordered(value[k]) for k in reversed(list(value))}
    return [_reordered(v) for v in value] if isinstance(value, list) else value


def _each_value_changed(value):
    """Copies of ``value``, one for each value in it (at any depth), with that value changed."""
    if isinstance(value, dict):
        for key, v in value.items():
            yield from ({**value, key: changed} for changed in _each_value_changed(v))
    elif isinstance(value, list):
        for i, v in enumerate(value):
            yield from (value[:i] + [changed] + value[i + 1:] for changed in _each_value_changed(v))
    else:
        yield value + ("x" if isinstance(value, str) else 1)


@pytest.mark.parametrize("config", [{"name": "csrt"}, {"name": "x", "regularizers": ["l2"]}, {"features": 3},
                                    {"features": [{"nome": "gray"}], "label": "gaussian"}])
def test_configs_that_are_not_dcfkit_trackers_still_hash(config):
    """Configs the registry cannot read (an OpenCV baseline, a typo) still key their results:
    the key is 16 hex digits, the same for the same config with its keys in another order
    or another name, and different when any other value in it changes."""
    import re

    from dcfkit.store.provenance import run_key

    digest = run_key(config)
    assert re.fullmatch(r"[0-9a-f]{16}", digest)
    assert run_key(_reordered(config)) == digest
    assert run_key({**config, "name": "renamed"}) == digest
    changed = [c for c in _each_value_changed({k: v for k, v in config.items() if k != "name"})]
    assert all(run_key({**c, "name": config.get("name")}) != digest for c in changed), changed


def _entry_point(monkeypatch, name, source):
    """An entry point whose module runs ``source`` (as file '<string>') when it is loaded."""
    ep = install_plugin(monkeypatch, name, "")

    def load():
        module = types.ModuleType(name)
        exec(compile(source, "<string>", "exec"), module.__dict__)
        return module
    ep.load = load
    return ep


def _build_or_fail():
    """build_registry, with an escaping KeyboardInterrupt a test failure (not the end of the run)."""
    try:
        return reg.build_registry()
    except KeyboardInterrupt as exc:
        pytest.fail(f"{exc!r} escaped the registry")


@pytest.mark.parametrize("source, message", [
    ("raise KeyboardInterrupt", r"'dcfkit_test_ctrl_c \(dcfkit_test_ctrl_c\)' could not be imported and was "
                                r"skipped: KeyboardInterrupt \(at <string>:1\)"),
    ("raise SystemExit('bye')", r"could not be imported and was skipped: SystemExit: bye \(at <string>:1\)"),
    (PLUGIN.replace("registry.register(Flat)", "registry.register(Flat)\n    raise KeyboardInterrupt('in the hook')"),
     r"'dcfkit_test_ctrl_c \(dcfkit_test_ctrl_c\)' failed and was skipped: KeyboardInterrupt: in the hook "
     r"\(at <string>:\d+\)"),
])
def test_a_plugin_raising_keyboard_interrupt_is_named_and_skipped(monkeypatch, source, message):
    """It used to escape the registry: every command printed 'interrupted' and nothing named the plugin."""
    ep = _entry_point(monkeypatch, "dcfkit_test_ctrl_c", source)
    with_entry_points(monkeypatch, [ep, install_plugin(monkeypatch, "dcfkit_test_good2", PLUGIN)])
    with pytest.warns(reg.PluginWarning, match=message):
        r = _build_or_fail()
    assert "flat" in r.names("label") and "gaussian" in r.names("label")  # the other plugin's, undone ones' not


BOOM = "class Boom(BaseException):\n    pass\n"


@pytest.mark.parametrize("source, message", [
    (BOOM + "raise Boom('at import')", r"'dcfkit_test_base \(dcfkit_test_base\)' could not be imported and was "
                                       r"skipped: Boom: at import \(at <string>:3\)"),
    ("raise GeneratorExit", r"could not be imported and was skipped: GeneratorExit \(at <string>:1\)"),
    (BOOM + PLUGIN.replace("registry.register(Flat)", "registry.register(Flat)\n    raise Boom('in the hook')"),
     r"'dcfkit_test_base \(dcfkit_test_base\)' failed and was skipped: Boom: in the hook \(at <string>:\d+\)"),
])
def test_a_plugin_raising_another_base_exception_is_named_and_skipped(monkeypatch, source, message):
    """A BaseException that is neither SystemExit nor KeyboardInterrupt (a class of the plugin's,
    GeneratorExit) escaped the registry: every command ended in a traceback."""
    ep = _entry_point(monkeypatch, "dcfkit_test_base", source)
    with_entry_points(monkeypatch, [ep, install_plugin(monkeypatch, "dcfkit_test_good3", PLUGIN)])
    with pytest.warns(reg.PluginWarning, match=message):
        r = reg.build_registry()
    assert "flat" in r.names("label") and "gaussian" in r.names("label")  # the other plugin's flat stays


def test_every_command_names_a_plugin_that_raises_a_base_exception(monkeypatch, capsys):
    from dcfkit import cli

    with_entry_points(monkeypatch, [_entry_point(monkeypatch, "dcfkit_test_base2", BOOM + "raise Boom")])
    monkeypatch.setattr(reg, "_REGISTRY", None)
    with warnings.catch_warnings():
        warnings.simplefilter("always")
        status = cli.main(["track", "strcf", "--frames", "/nonexistent", "--box", "1,1,5,5"])
    err = capsys.readouterr().err
    assert status == 2 and "error: " in err and "Traceback" not in err
    assert "warning: dcfkit plugin 'dcfkit_test_base2 (dcfkit_test_base2)' could not be imported and was " \
           "skipped: Boom (at <string>:3)" in err
    monkeypatch.setattr(reg, "_REGISTRY", None)


def test_every_command_names_a_plugin_that_raises_keyboard_interrupt(monkeypatch, capsys):
    from dcfkit import cli

    with_entry_points(monkeypatch, [install_plugin(monkeypatch, "dcfkit_test_ctrl_c2", PLUGIN.replace(
        "registry.register(Flat)", "raise KeyboardInterrupt"))])
    monkeypatch.setattr(reg, "_REGISTRY", None)
    with warnings.catch_warnings():
        warnings.simplefilter("always")
        status = cli.main(["components", "--kind", "label"])
    err = capsys.readouterr().err
    assert status == 1 and "interrupted" not in err
    assert "warning: dcfkit plugin 'dcfkit_test_ctrl_c2 (dcfkit_test_ctrl_c2)' failed and was skipped: " \
           "KeyboardInterrupt (at " in err
    monkeypatch.setattr(reg, "_REGISTRY", None)


@pytest.mark.parametrize("signal_name", ["SIGINT", "SIGTERM"])
def test_a_real_interrupt_while_a_plugin_loads_still_interrupts(monkeypatch, signal_name):
    """Ctrl-C (or SIGTERM, which the commands turn into an interrupt) arriving while a plugin is
    imported is the user's: it ends the command, and is not blamed on the plugin."""
    import signal

    from dcfkit.signals import Interrupted, interrupt_on_termination

    if signal.getsignal(signal.SIGINT) is not signal.default_int_handler:
        pytest.skip("Ctrl-C is not Python's default KeyboardInterrupt here")
    source = f"import os, signal, time\nos.kill(os.getpid(), signal.{signal_name})\ntime.sleep(5)\n"
    with_entry_points(monkeypatch, [_entry_point(monkeypatch, "dcfkit_test_signalled", source)])
    with interrupt_on_termination(), pytest.raises(KeyboardInterrupt) as raised:
        reg.build_registry()
    assert isinstance(raised.value, Interrupted) == (signal_name == "SIGTERM")


def test_plugins_load_off_the_main_thread_as_a_dask_worker_does():
    """Dask runs tasks in worker threads, where signal handlers cannot be set: loading the
    registry there must not try."""
    import threading

    outcome = []

    def load():
        try:
            outcome.append(sorted(reg.build_registry(external=False).names("label")))
        except Exception as exc:  # noqa: BLE001 - the test reports it
            outcome.append(exc)

    worker = threading.Thread(target=load)
    worker.start()
    worker.join()
    assert outcome and not isinstance(outcome[0], Exception), outcome
    assert "gaussian" in outcome[0]


def test_without_its_own_entry_point_dcfkit_says_to_install_it(monkeypatch):
    monkeypatch.setattr(importlib.metadata, "entry_points", lambda group=None: [])  # a folder on sys.path, not installed
    with pytest.raises(RegistryError, match=r"dcfkit's own plugin \(entry point 'builtin' of group 'dcfkit'\) is not "
                                            r"installed.*pip install -e \."):
        reg.build_registry()
