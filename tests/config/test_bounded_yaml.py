"""Hostile configs, ablation specs and --set values (issue 15): each ends in dcfkit's own
ConfigError naming the file and key (or the --set argument), in little memory and few steps
(values composed, measured and copied: :class:`Steps`), never in a number of seconds: what
grows in a bomb is counted, whatever the CPU.

What could hang or eat the machine (alias bombs, huge grids) runs in a forked child with a cap
on its address space and a watchdog far beyond any refusal (:func:`bounded`), so that the old
code fails these tests instead of hanging them.
"""
from __future__ import annotations

import multiprocessing
import resource
import sys
import tracemalloc
from pathlib import Path

import pytest
import yaml
from hypothesis import given
from hypothesis import strategies as st

from dcfkit import config
from dcfkit.ablation import load_spec
from dcfkit.config import bounded_yaml, load_config
from dcfkit.config.overrides import parse_overrides
from dcfkit.errors import ConfigError, DcfkitError, RegistryError

CONFIGS = Path(__file__).resolve().parents[2] / "configs"
SHIPPED = sorted(CONFIGS.glob("*.yaml")) + sorted((CONFIGS / "reference").glob("*.yaml"))
# Steps (below) of one load: each of its at most MAX_VALUES values is composed, measured and
# copied once or twice; the most any test here takes is 3,087, a bomb expanded takes millions
STEPS = 5 * bounded_yaml.MAX_VALUES
PEAK_BYTES = 30 * 2**20  # Python allocations of one refusal (tracemalloc's peak); a bomb wanted GBs
MESSAGE_CHARS = 1000  # an error message, whatever the size of the value it is about

pytestmark = pytest.mark.skipif(sys.platform == "win32", reason="bounded() forks")


class TooManySteps(BaseException):
    """Raised by :class:`Steps` past its limit: not an Exception, so no handler in dcfkit takes it."""


class Steps:
    """Counts the loader's steps in the block: YAML nodes composed, values measured against the
    bounds (a shared part once) and values copied out of the document (an alias at each use).
    A bomb grows them with its expansion (a walk without memo, a copy before the count, a grid
    made point by point), deterministically: they are the same on any machine. Past ``limit``
    the step raises :class:`TooManySteps`, so a bomb the bounds miss ends at once."""

    COUNTED = [(yaml.composer.Composer, "compose_node"), (bounded_yaml, "_node_items"),
               (bounded_yaml, "_python_items"), (bounded_yaml, "unshared")]

    def __init__(self, limit: int = STEPS):
        self.limit = limit

    def __enter__(self):
        self.count = 0
        self._real = [(owner, name, getattr(owner, name)) for owner, name in self.COUNTED]
        for owner, name, real in self._real:
            setattr(owner, name, self._counted(real))
        return self

    def _counted(self, real):
        def counted(*args, **kwargs):
            self.count += 1
            if self.count > self.limit:
                raise TooManySteps(f"more than {self.limit} steps")
            return real(*args, **kwargs)
        return counted

    def __exit__(self, *exc):
        for owner, name, real in self._real:
            setattr(owner, name, real)


def _child(send, fn, args) -> None:
    """In the forked child: run ``fn(*args)`` under an address-space cap, send back how it went."""
    _, hard = resource.getrlimit(resource.RLIMIT_AS)
    with open("/proc/self/statm") as statm:
        now = int(statm.read().split()[0]) * resource.getpagesize()
    cap = now + 2**30  # 1 GB more than the forked test process: a bomb stops here, not at the machine's end
    resource.setrlimit(resource.RLIMIT_AS, (cap if hard == resource.RLIM_INFINITY else min(cap, hard), hard))
    tracemalloc.start()
    with Steps() as steps:
        try:
            fn(*args)
            kind, message = "ok", ""
        except BaseException as exc:  # the parent judges whatever it was (MemoryError, RecursionError...)
            kind, message = type(exc).__name__, str(exc)
    send.send((kind, message[:5000], len(message), steps.count, tracemalloc.get_traced_memory()[1]))


def bounded(fn, *args, seconds: float = 60.0) -> dict:
    """``fn(*args)`` in a forked child: its outcome ('ok', the exception's type name, or 'hung'
    when killed after ``seconds``), message, message length, steps and peak traced bytes.
    ``seconds`` is a watchdog for a bomb that neither ends nor fills the address space, not a
    measure: a refusal takes milliseconds and its steps are what the tests bound."""
    ctx = multiprocessing.get_context("fork")
    receive, send = ctx.Pipe(duplex=False)
    child = ctx.Process(target=_child, args=(send, fn, args), daemon=True)
    child.start()
    send.close()
    try:
        if not receive.poll(seconds):
            return {"kind": "hung", "message": f"no answer after {seconds} s", "length": 0,
                    "steps": None, "peak": None}
        kind, message, length, steps, peak = receive.recv()
        return {"kind": kind, "message": message, "length": length, "steps": steps, "peak": peak}
    except EOFError:  # the child died without answering (killed by the address-space cap)
        return {"kind": "died", "message": "", "length": 0, "steps": None, "peak": None}
    finally:
        child.kill()
        child.join()
        receive.close()


def assert_refused(outcome: dict, *parts: str) -> None:
    """A ConfigError that names ``parts``, within the step, memory and message bounds."""
    assert outcome["kind"] == "ConfigError", outcome
    for part in parts:
        assert part in outcome["message"], outcome
    assert outcome["steps"] < STEPS and outcome["peak"] < PEAK_BYTES, outcome
    assert outcome["length"] < MESSAGE_CHARS, outcome


def alias_bomb(levels: int = 9, fan: int = 9) -> str:
    """A flow list whose anchors each repeat the previous one ``fan`` times: fan**levels leaves."""
    text = "&a0 [" + ",".join(["lol"] * fan) + "]"
    for i in range(1, levels):
        text = f"&a{i} [{text}" + f",*a{i - 1}" * (fan - 1) + "]"
    return text


def test_the_bomb_of_the_report_is_that_small():
    assert len(alias_bomb()) < 400  # the 369-character --set value; 9**9 = 387 million leaves


# --------------------------------------------------------------------------- 1. alias bombs


@pytest.mark.parametrize("text,key", [
    ("base: strcf\nname: {bomb}\n", "name"),
    ("base: strcf\ndescription: {bomb}\n", "description"),
    ("base: strcf\ntracker: {bomb}\n", "tracker"),
    ("base: dr2track\nlabel: {{mu: {bomb}}}\n", "label.mu"),
    ("base: strcf\nfeatures: [{{name: gray}}, {bomb}]\n", "features.1"),
])
def test_alias_bombs_in_a_config_are_refused_in_few_steps(tmp_path, text, key):
    path = tmp_path / "bomb.yaml"
    path.write_text(text.format(bomb=alias_bomb()))
    assert path.stat().st_size < 1024
    assert_refused(bounded(load_config, path), str(path), key, "dcfkit.config.bounded_yaml.MAX_VALUES")


def test_a_merge_key_bomb_is_refused_in_few_steps(tmp_path):
    # PyYAML copies merged pairs (<<) while it builds the document: 2**40 pairs from 1.5 KB
    lines = ["  m0: &m0 {k: 1}"] + [f"  m{i}: &m{i} {{<<: [*m{i - 1}, *m{i - 1}], k{i}: 1}}" for i in range(1, 40)]
    path = tmp_path / "merge.yaml"
    path.write_text("base: strcf\nx:\n" + "\n".join(lines) + "\n")
    assert_refused(bounded(load_config, path), str(path), "x", "dcfkit.config.bounded_yaml.MAX_VALUES")


def _track_with_set(argument: str) -> None:
    """What ``dcfkit track CONFIG --set argument`` and ``dcfkit eval --set`` do with it."""
    load_config("dr2track", parse_overrides([argument]))


@pytest.mark.parametrize("key", ["name", "description", "label.mu"])
def test_an_alias_bomb_as_a_set_value_is_refused_in_few_steps(key):
    assert_refused(bounded(_track_with_set, f"{key}={alias_bomb()}"), f"--set {key}",
                   "dcfkit.config.bounded_yaml.MAX_VALUES")


@pytest.mark.parametrize("text,key", [
    ("dataset: otb\ndescription: {bomb}\nvariants: {{a: dr2track}}\n", "description"),
    ("dataset: otb\nvariants:\n  a: {{config: dr2track, overrides: {{label.mu: {bomb}}}}}\n", "variants.a.overrides"),
])
def test_alias_bombs_in_an_ablation_spec_are_refused_in_few_steps(tmp_path, text, key):
    path = tmp_path / "spec.yaml"
    path.write_text(text.format(bomb=alias_bomb()))
    assert_refused(bounded(load_spec, path), str(path), key, "dcfkit.config.bounded_yaml.MAX_VALUES")


def test_aliases_of_a_long_text_are_refused_in_few_steps(tmp_path):
    # few values, but 200 MB of text once written out (the grid names its variants by their values)
    path = tmp_path / "spec.yaml"
    path.write_text("dataset: otb\ngrid:\n  base: dr2track\n  parameters:\n    description: [[&s " + "x" * 100_000
                    + ", " + ", ".join(["*s"] * 2000) + "]]\n")
    assert_refused(bounded(load_spec, path), str(path), "grid.parameters.description",
                   "dcfkit.config.bounded_yaml.MAX_TEXT")


def test_an_alias_inside_its_own_anchor_is_refused(tmp_path):
    path = tmp_path / "self.yaml"
    path.write_text("base: dr2track\nlabel: {mu: &m [1, *m]}\n")
    with pytest.raises(ConfigError, match=r"self.yaml:2:\d+: label.mu.1: contains itself"):
        load_config(path)
    with pytest.raises(ConfigError, match=r"--set label.mu: .*contains itself"):
        parse_overrides(["label.mu=&m [1, *m]"])


def test_anchors_still_work_and_an_override_changes_one_place(tmp_path):
    # aliases are legitimate YAML; now each is a copy, so --set features.0.name changes one feature
    path = tmp_path / "anchors.yaml"
    path.write_text("base: strcf\nfeatures: [&g {name: gray}, *g]\n")
    assert [f["name"] for f in load_config(path)["features"]] == ["gray", "gray"]
    assert [f["name"] for f in load_config(path, {"features.0.name": "fhog"})["features"]] == ["fhog", "gray"]
    spec = tmp_path / "spec.yaml"
    spec.write_text("dataset: otb\nvariants:\n  a: {config: dr2track, overrides: &o {label.mu: 0.3}}\n"
                    "  b: {config: dr2track, overrides: *o}\n")
    assert [v.config["label"]["mu"] for v in load_spec(spec).variants] == [0.3, 0.3]


def _alias_document(levels: int, fan: int, merge: bool) -> tuple[str, int]:
    """A YAML flow value of anchors on anchors, and its number of leaves once expanded: ``fan ** levels``
    of plain aliases; of merge keys one per key (``k``, ``k1`` ...), as each merge keeps one value a key."""
    if merge:
        text = "&a0 {k: 1}"
        for i in range(1, levels):
            text = f"&a{i} {{<<: [{text}" + f", *a{i - 1}" * (fan - 1) + f"], k{i}: 1}}"
    else:
        text = alias_bomb(levels, fan)
    return text, levels if merge else fan ** levels


def _load_with_value(tmp_path: Path, place: str, value: str):
    """Put ``value`` at ``place`` of a config, a spec or a --set argument, and load that."""
    if place == "--set":
        return lambda: load_config("dr2track", parse_overrides([f"label.mu={value}"]))
    path = tmp_path / f"{place}.yaml"
    if place == "spec":
        path.write_text(f"dataset: otb\ndescription: {value}\nvariants: {{a: strcf}}\n")
        return lambda: load_spec(path)
    path.write_text(f"base: dr2track\n{place}: {value}\n" if "." not in place else
                    f"base: dr2track\nlabel: {{mu: {value}}}\n")
    return lambda: load_config(path)


@given(levels=st.integers(1, 12), fan=st.integers(1, 9), merge=st.booleans(),
       place=st.sampled_from(["name", "description", "tracker", "label.mu", "spec", "--set"]))
def test_any_alias_document_is_loaded_or_refused_in_few_steps(tmp_path_factory, levels, fan, merge, place):
    value, leaves = _alias_document(levels, fan, merge)
    outcome = bounded(_load_with_value(tmp_path_factory.mktemp("alias"), place, value))
    assert outcome["kind"] in ("ok", "ConfigError"), outcome
    assert outcome["steps"] < STEPS and outcome["peak"] < PEAK_BYTES and outcome["length"] < MESSAGE_CHARS, outcome
    if leaves > bounded_yaml.MAX_VALUES:
        assert "MAX_VALUES" in outcome["message"], outcome


# --------------------------------------------------------------------------- 3. deep nesting


DEEP = 3000  # far past Python's recursion limit of 1000


def test_a_deeply_nested_set_value_is_a_config_error():
    with pytest.raises(ConfigError, match=r"--set label.mu: nested more than \d+ levels deep"):
        parse_overrides(["label.mu=" + "[" * DEEP + "]" * DEEP])
    with pytest.raises(ConfigError, match=r"--set label.mu: nested more than \d+ levels deep"):
        parse_overrides(["label.mu=" + "{a: " * DEEP + "1" + "}" * DEEP])


def test_a_deeply_nested_config_file_is_a_config_error(tmp_path):
    path = tmp_path / "deep.yaml"
    path.write_text("base: dr2track\nlabel: {mu: " + "[" * DEEP + "]" * DEEP + "}\n")
    with pytest.raises(ConfigError, match=r"deep.yaml:\d+:\d+: nested more than \d+ levels deep"):
        load_config(path)
    path.write_text("base: dr2track\nlabel:\n" + "".join("  " * i + f"  k{i}:\n" for i in range(200)) + "\n")
    with pytest.raises(ConfigError, match=r"deep.yaml:\d+:\d+: nested more than \d+ levels deep"):
        load_config(path)


def test_deeply_nested_values_from_python_are_config_errors():
    deep: list = []
    for _ in range(DEEP):
        deep = [deep]
    with pytest.raises(ConfigError, match=r"<config dict>: label.x.0.0.*: nested more than \d+ levels deep"):
        load_config({"base": "strcf", "label": {"name": "gaussian", "x": deep}})
    with pytest.raises(ConfigError, match=r"override 'label.mu': 0.0.*: nested more than \d+ levels deep"):
        load_config("dr2track", {"label.mu": deep})
    with pytest.raises(ConfigError, match=r"strcf.yaml: tracker.cell_size.a.a.*: nested more than \d+ levels deep"):
        load_config("strcf", {"tracker.cell_size" + ".a" * DEEP: 1})
    looped: dict = {"name": "gaussian"}
    looped["self"] = looped
    with pytest.raises(ConfigError, match=r"<config dict>: label.self: contains itself"):
        load_config({"base": "strcf", "label": looped})


def test_a_long_base_chain_is_a_config_error(tmp_path):
    (tmp_path / "c0.yaml").write_text("base: strcf\n")
    for i in range(1, 1500):
        (tmp_path / f"c{i}.yaml").write_text(f"base: c{i - 1}.yaml\n")
    with Steps() as steps, pytest.raises(ConfigError, match=r"c1499.yaml: the 'base' chain is longer than \d+ files"):
        load_config(tmp_path / "c1499.yaml")
    assert steps.count < 1000  # 8 steps a file for the 32 read (MAX_BASE_CHAIN), not for all 1500


def test_deeply_nested_ablation_overrides_are_config_errors(tmp_path):
    spec = tmp_path / "spec.yaml"
    spec.write_text("dataset: otb\nvariants:\n  a: {config: dr2track, overrides: {label.mu: "
                    + "[" * DEEP + "]" * DEEP + "}}\n")
    with pytest.raises(ConfigError, match=r"spec.yaml:\d+:\d+: nested more than \d+ levels deep"):
        load_spec(spec)
    spec.write_text("dataset: otb\nvariants:\n  a:\n    config: dr2track\n    overrides:\n      label.mu"
                    + ".x" * 300 + ": 1\n")  # PyYAML's keys end at 1024 characters
    with pytest.raises(ConfigError, match=r"spec.yaml: variants.a overrides .*dr2track.yaml: label.mu.x.x.*nested"):
        load_spec(spec)


# --------------------------------------------------------------------------- the bounds


def test_the_bounds_are_where_the_docs_say_and_can_be_raised(monkeypatch, tmp_path):
    depth = bounded_yaml.MAX_DEPTH
    assert config.parse_value("[" * depth + "1" + "]" * depth) is not None
    with pytest.raises(ConfigError, match="dcfkit.config.bounded_yaml.MAX_DEPTH"):
        config.parse_value("[" * (depth + 1) + "1" + "]" * (depth + 1))
    many = "[" + ", ".join(["1"] * bounded_yaml.MAX_VALUES) + "]"  # the list and its items: one value too many
    with pytest.raises(ConfigError, match="dcfkit.config.bounded_yaml.MAX_VALUES"):
        config.parse_value(many)
    fewer = bounded_yaml.MAX_VALUES - 1
    assert len(config.parse_value("[" + ", ".join(["1"] * fewer) + "]")) == fewer
    monkeypatch.setattr(bounded_yaml, "MAX_VALUES", 2 * bounded_yaml.MAX_VALUES)
    assert len(config.parse_value(many)) == bounded_yaml.MAX_VALUES // 2
    (tmp_path / "c0.yaml").write_text("base: strcf\n")
    for i in range(1, config.MAX_BASE_CHAIN):  # strcf.yaml and c0 ... c30: the longest chain
        (tmp_path / f"c{i}.yaml").write_text(f"base: c{i - 1}.yaml\n")
    assert load_config(tmp_path / f"c{config.MAX_BASE_CHAIN - 2}.yaml") == load_config("strcf")
    with pytest.raises(ConfigError, match="dcfkit.config.MAX_BASE_CHAIN"):
        load_config(tmp_path / f"c{config.MAX_BASE_CHAIN - 1}.yaml")


def test_huge_files_are_refused_without_reading_them(tmp_path):
    huge = tmp_path / "huge.yaml"
    with open(huge, "wb") as file:
        file.truncate(2**33)  # 8 GB, sparse
    tracemalloc.start()
    try:
        with pytest.raises(ConfigError,
                           match=r"huge.yaml: larger than \d+ bytes \(dcfkit.config.bounded_yaml.MAX_YAML_BYTES\)"):
            load_config(huge)
        with pytest.raises(ConfigError, match=r"huge.yaml: larger than"):
            load_spec(huge)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak < 2 * bounded_yaml.MAX_YAML_BYTES  # its first MAX_YAML_BYTES + 1 bytes read, no more
    with pytest.raises(ConfigError, match=r"--set name: longer than \d+ characters"):
        parse_overrides(["name=" + "x" * (bounded_yaml.MAX_YAML_BYTES + 1)])


def test_a_huge_product_grid_is_refused_before_it_is_made(tmp_path):
    spec = tmp_path / "spec.yaml"
    values = "[" + ", ".join(str(i) for i in range(1, 101)) + "]"  # each point valid: the old code tried them all
    spec.write_text(f"dataset: otb\ngrid:\n  base: dr2track\n  mode: product\n  parameters:\n"
                    f"    label.mu: {values}\n    label.top_n: {values}\n    solver.iterations: {values}\n")
    assert_refused(bounded(load_spec, spec), str(spec), "grid.parameters: 1000000 grid points",
                   "dcfkit.ablation.spec.MAX_VARIANTS")


def test_long_values_are_shown_short_in_messages(tmp_path):
    path = tmp_path / "long.yaml"
    path.write_text("base: dr2track\nlabel: {mu: " + "x" * 200_000 + "}\n")
    with pytest.raises(ConfigError, match=r"long.yaml: label .*mu: expected a number, got 'xxx+\.\.\.") as info:
        load_config(path)
    assert len(str(info.value)) < MESSAGE_CHARS
    with pytest.raises(ConfigError) as info:
        load_config("dr2track", {"label.mu": list(range(100_000))})
    assert len(str(info.value)) < MESSAGE_CHARS
    with pytest.raises(ConfigError) as info:
        load_config("strcf", {"name": 10**5000})  # too long for repr() itself
    assert "name: expected a string, got <int>" in str(info.value)


# --------------------------------------------------------------------------- 7a. a null section


@pytest.mark.parametrize("text,key", [
    ("label: null\n", "label"), ("solver: null\n", "solver"), ("search: null\n", "search"),
    ("scale: 5\n", "scale"), ("features: [null]\n", r"features\[0\]"),
])
def test_a_null_or_scalar_section_is_a_config_error(tmp_path, text, key):
    path = tmp_path / "null.yaml"
    path.write_text("base: strcf\n" + text)
    with pytest.raises(ConfigError, match=rf"null.yaml: {key}: expected a mapping with a 'name' key"):
        load_config(path)


# --------------------------------------------------------------------------- properties


def _any_value():
    """Small YAML-able values of every type, some of them awkward."""
    leaves = st.one_of(st.none(), st.booleans(), st.integers(), st.floats(), st.text(max_size=20),
                       st.sampled_from([10**400, "1e400", "-inf", "nan", "", "gaussian", "admm_strcf", "2001-13-45"]))
    return st.recursive(leaves, lambda inner: st.lists(inner, max_size=4)
                        | st.dictionaries(st.text(max_size=8), inner, max_size=4), max_leaves=8)


def _paths(value, prefix=()):
    """Every (path, container) below ``value``: the places a mutation can act."""
    yield prefix, value
    items = value.items() if isinstance(value, dict) else enumerate(value) if isinstance(value, list) else ()
    for key, child in items:
        if isinstance(child, (dict, list)):
            yield from _paths(child, prefix + (key,))


@st.composite
def mutated_config(draw):
    """A shipped config (as a dict) with random deletions, insertions, type changes and deep nests."""
    data = yaml.safe_load(draw(st.sampled_from(SHIPPED)).read_text(encoding="utf-8"))
    for _ in range(draw(st.integers(1, 4))):
        _, node = draw(st.sampled_from(list(_paths(data))))
        keys = list(node) if isinstance(node, dict) else list(range(len(node)))
        op = draw(st.sampled_from(["delete", "insert", "change", "nest"]))
        key = draw(st.sampled_from(keys)) if keys and op != "insert" else draw(st.text(max_size=8))
        if op == "delete" and keys:
            del node[key]
        elif isinstance(node, dict) or keys:
            value = draw(_any_value()) if op != "nest" else ("nest", draw(st.integers(20, DEEP)))
            node[key if isinstance(node, dict) or op != "insert" else 0] = value
    return data


def _nest(value):
    """``("nest", n)`` placeholders as n nested lists (Python), everything else as it is."""
    if isinstance(value, tuple) and value[:1] == ("nest",):
        out: list = []
        for _ in range(value[1]):
            out = [out]
        return out
    if isinstance(value, dict):
        return {k: _nest(v) for k, v in value.items()}
    return [_nest(v) for v in value] if isinstance(value, list) else value


def _as_yaml(value) -> str:
    """YAML text of ``value``, a ``("nest", n)`` placeholder written as n nested flow lists."""
    nests = []

    def hide(v):
        if isinstance(v, tuple) and v[:1] == ("nest",):
            nests.append(v[1])
            return f"NEST{len(nests) - 1}X"
        if isinstance(v, dict):
            return {k: hide(x) for k, x in v.items()}
        return [hide(x) for x in v] if isinstance(v, list) else v

    text = yaml.safe_dump(hide(value), allow_unicode=True)
    for i, n in enumerate(nests):
        text = text.replace(f"NEST{i}X", "[" * n + "]" * n)
    return text


def assert_config_error_or_unknown_name(exc: DcfkitError) -> None:
    """ConfigError; a RegistryError only for a component name that is unknown (its documented type)."""
    assert isinstance(exc, ConfigError) or (isinstance(exc, RegistryError) and ".name: unknown " in str(exc)), \
        repr(exc)
    assert len(str(exc)) < MESSAGE_CHARS


@given(data=mutated_config(), as_file=st.booleans(), junk=st.one_of(st.none(), st.tuples(st.integers(0, 3000),
                                                                                          st.binary(max_size=40))))
def test_a_mutated_shipped_config_loads_or_is_a_config_error(tmp_path_factory, data, as_file, junk):
    with Steps() as steps:
        try:
            if as_file or junk:
                raw = _as_yaml(data).encode("utf-8")
                if junk:  # cut the text there and put bytes in: syntax errors, binary junk, not UTF-8
                    raw = raw[:junk[0]] + junk[1] + raw[junk[0]:]
                path = tmp_path_factory.mktemp("mutated") / "mutated.yaml"
                path.write_bytes(raw)
                load_config(path)
            else:
                load_config(_nest(data))
        except DcfkitError as exc:
            assert_config_error_or_unknown_name(exc)
    assert steps.count < STEPS


YAML_BITS = ["[", "]", "{", "}", ", ", ": ", "- ", "\n", "  ", "&a ", "*a", "&b ", "*b", "<<: ", "? ", "'", '"',
             "!!binary ", "!!set ", "!!omap ", "!!float ", "!!python/object ", "#", "|", ">", "%YAML 1.1\n", "---",
             "1e400", "9" * 5000, "2001-13-45", "x", "1", "null", "\x00", "\ud800", "[" * 600, "]" * 600]


@given(st.one_of(st.text(max_size=300), st.lists(st.sampled_from(YAML_BITS), max_size=60).map("".join)),
       st.sampled_from(["label.mu", "description", "tracker", "features", "solver.iterations"]))
def test_any_set_value_is_parsed_or_a_config_error(text, key):
    with Steps() as steps:
        try:
            overrides = parse_overrides([f"{key}={text}"])
            load_config("dr2track", overrides)
        except DcfkitError as exc:
            assert_config_error_or_unknown_name(exc)
            if "--set" in str(exc):
                assert f"--set {key}" in str(exc)
    assert steps.count < STEPS


def test_a_400_digit_integer_for_a_float_parameter_is_a_config_error():
    import dcfkit

    with pytest.raises(ConfigError, match=r"solver.*beta.*expected a finite number"):
        dcfkit.load_tracker("strcf", overrides={"solver.beta": int("9" * 400)})
