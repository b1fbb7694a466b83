"""YAML read within bounds: size, values, text and depth (docs/hardening.md). The limits are
read when used: a program that needs more sets e.g. ``dcfkit.config.bounded_yaml.MAX_VALUES =
10**6``."""
from __future__ import annotations

from pathlib import Path
from typing import Any, Mapping

import yaml

from dcfkit.errors import ConfigError, clip, shown

# Bounds on what a config, an ablation spec or a --set value may be, far beyond any real one
# (the shipped configs and specs: at most 6.4 KB, 409 values, 5 levels). Read when used: a program
# that needs more sets e.g. ``dcfkit.config.bounded_yaml.MAX_VALUES = 10**6`` before loading.
MAX_YAML_BYTES = 256 * 1024  # a YAML file or --set value (PyYAML takes up to 0.3 s to read that here)


MAX_VALUES = 10_000  # mappings, lists, keys and scalars in one document or value, an alias counted at each use


MAX_TEXT = 1024 * 1024  # characters of the scalars in one document or value, an alias counted at each use


MAX_DEPTH = 32  # levels of mappings and lists nested in one another


DEEP = "nested more than {} levels deep (dcfkit.config.bounded_yaml.MAX_DEPTH)"


LARGE = ("more than {} values, each alias counted as the values it stands for "
         "(dcfkit.config.bounded_yaml.MAX_VALUES)")


LONG = ("more than {} characters, each alias counted as the text it stands for "
        "(dcfkit.config.bounded_yaml.MAX_TEXT)")


class OverLimit(Exception):
    """A value over one of the bounds above: ``problem`` says which, ``path`` lists the keys
    down to the part refused, ``at`` is that part (a YAML node while loading)."""

    def __init__(self, problem: str, path: list, at: Any = None):
        super().__init__(problem)
        self.problem, self.path, self.at = problem, list(path), at

    def describe(self) -> str:
        """``dotted.key: problem`` (the problem alone for the whole value)."""
        key = clip(".".join(clip(str(p)) for p in self.path))
        return f"{key}: {self.problem}" if key else self.problem


def _measure(root: Any, items) -> None:
    """Raise :class:`OverLimit` if ``root`` nests deeper than MAX_DEPTH, holds more than
    MAX_VALUES values or MAX_TEXT characters with a shared part counted at each use, or
    contains itself.

    ``items(x)`` lists a container's ``(key, child)`` pairs, or gives a scalar's length in
    characters. A shared part is walked once (memoised by identity), so an alias bomb costs the
    time of its source, not of its expansion, and the recursion is never deeper than MAX_DEPTH.
    """
    known: dict[int, tuple[int, int, int] | None] = {}  # id -> (values, characters, height); None while inside
    path: list = []

    def visit(item: Any) -> tuple[int, int, int]:
        if id(item) not in known:  # the structure keeps its parts alive: an id is not reused meanwhile
            children = items(item)
            if isinstance(children, int):
                return 1, children, 0
            known[id(item)] = None
            known[id(item)] = add_up(item, children)
        if known[id(item)] is None:
            raise OverLimit("contains itself (an alias inside its own anchor)", path, item)
        values, characters, height = known[id(item)]
        if len(path) + height > MAX_DEPTH:
            raise OverLimit(DEEP.format(MAX_DEPTH), path, item)
        return values, characters, height

    def add_up(item: Any, children: list) -> tuple[int, int, int]:
        if len(path) >= MAX_DEPTH:
            raise OverLimit(DEEP.format(MAX_DEPTH), path, item)
        values, characters, height = 1, 0, 0
        for key, child in children:
            path.append(key)
            more, longer, below = visit(child)
            path.pop()
            values, characters, height = values + more, characters + longer, max(height, below + 1)
            if values > MAX_VALUES:
                raise OverLimit(LARGE.format(MAX_VALUES), path, item)
            if characters > MAX_TEXT:
                raise OverLimit(LONG.format(MAX_TEXT), path, item)
        return values, characters, height

    visit(root)


def _node_items(node: yaml.Node) -> list | int:
    """A YAML node's ``(key, child)`` pairs (a mapping's keys are children too), or a scalar's length."""
    if isinstance(node, yaml.SequenceNode):
        return list(enumerate(node.value))
    if isinstance(node, yaml.MappingNode):
        pairs = [(k.value if isinstance(k, yaml.ScalarNode) else "?", k, v) for k, v in node.value]
        return [item for key, k, v in pairs for item in ((key, k), (key, v))]
    return len(node.value)


def _python_items(value: Any) -> list | int:
    """A config value's ``(key, child)`` pairs if a mapping, list or tuple; else its length if
    text, 1 for anything else."""
    if isinstance(value, Mapping):
        return [item for k, v in value.items() for item in ((k, k), (k, v))]
    if isinstance(value, (list, tuple)):
        return list(enumerate(value))
    return len(value) if isinstance(value, (str, bytes)) else 1


def check_value(value: Any, where: str) -> None:
    """A ConfigError naming ``where`` and the key if ``value`` (a config dict, an override) is
    nested too deeply, too large or contains itself: checked before anything walks it."""
    try:
        _measure(value, _python_items)
    except OverLimit as exc:
        raise ConfigError(f"{where}: {exc.describe()}") from None


class _BoundedLoader(yaml.SafeLoader):
    """safe_load within the bounds above; it also refuses a key given twice in one mapping (YAML
    keeps the last silently). The document is composed with nesting and node count bounded as it
    goes (the composer recurses), measured with its aliases expanded, and only then built:
    PyYAML copies what a merge key (``<<``) brings in while it builds, so a bomb is refused first."""

    def __init__(self, stream):
        super().__init__(stream)
        self._depth = self._nodes = 0

    def compose_node(self, parent, index):
        self._depth, self._nodes = self._depth + 1, self._nodes + 1
        try:
            if self._depth > MAX_DEPTH + 1:  # + 1: the scalars in the deepest list
                raise OverLimit(DEEP.format(MAX_DEPTH), [], self.peek_event())
            if self._nodes > MAX_VALUES:
                raise OverLimit(LARGE.format(MAX_VALUES), [], self.peek_event())
            return super().compose_node(parent, index)
        finally:
            self._depth -= 1

    def get_single_data(self):
        node = self.get_single_node()
        if node is None:
            return None
        _measure(node, _node_items)
        return unshared(self.construct_document(node))

    def construct_object(self, node, deep=False):
        try:
            return super().construct_object(node, deep)
        except (ValueError, OverflowError) as exc:  # an int over 4300 digits, a date such as 2001-13-45
            raise yaml.constructor.ConstructorError(None, None, f"cannot read this value: {exc}",
                                                    node.start_mark) from None

    def construct_mapping(self, node, deep=False):
        seen = set()
        pairs = node.value if isinstance(node, yaml.MappingNode) else ()  # not a mapping: PyYAML's error below
        for key_node, _ in pairs:  # the mapping's own scalar keys; merge keys (<<) may be overridden
            if not isinstance(key_node, yaml.ScalarNode) or key_node.tag == "tag:yaml.org,2002:merge":
                continue
            key = (key_node.tag, key_node.value)
            if key in seen:
                raise yaml.constructor.ConstructorError(
                    None, None, f"key {shown(key_node.value)} is given twice in this mapping", key_node.start_mark)
            seen.add(key)
        return super().construct_mapping(node, deep)


def unshared(value: Any) -> Any:
    """``value`` with its mappings and lists unshared: an alias is a copy, so that an override
    changes the one place it names (called on measured values only: bounded depth and size)."""
    if isinstance(value, dict):
        return {k: unshared(v) for k, v in value.items()}
    if isinstance(value, list):
        return [unshared(v) for v in value]
    return value


def load_yaml(text: str) -> Any:
    """``text`` read by :class:`_BoundedLoader`: raises yaml.YAMLError (not YAML) or :class:`OverLimit`."""
    if len(text) > MAX_YAML_BYTES:
        raise OverLimit(f"longer than {MAX_YAML_BYTES} characters (dcfkit.config.bounded_yaml.MAX_YAML_BYTES)", [])
    return yaml.load(text, Loader=_BoundedLoader)


def _at(where: str, mark) -> str:
    """``where:line:column`` of a YAML mark (None: ``where``)."""
    return f"{where}:{mark.line + 1}:{mark.column + 1}" if mark is not None else where


def read_yaml(path: Path) -> dict:
    """A config or spec file as a dict; a ConfigError names the file (and line) when it is
    unreadable, not UTF-8, not YAML, over a bound or not a mapping."""
    try:
        with open(path, "rb") as file:
            raw = file.read(MAX_YAML_BYTES + 1)
    except OSError as exc:
        raise ConfigError(f"cannot read config {path}: {exc.strerror}") from None
    if len(raw) > MAX_YAML_BYTES:
        raise ConfigError(f"{path}: larger than {MAX_YAML_BYTES} bytes (dcfkit.config.bounded_yaml.MAX_YAML_BYTES); "
                          f"is it a config?")
    try:
        data = load_yaml(raw.decode("utf-8"))
    except UnicodeDecodeError as exc:
        raise ConfigError(f"{path}: not a UTF-8 text file (byte {exc.start} is not UTF-8)") from None
    except OverLimit as exc:
        mark = getattr(exc.at, "start_mark", None)
        raise ConfigError(f"{_at(str(path), mark)}: {exc.describe()}") from None
    except yaml.YAMLError as exc:
        problem = getattr(exc, "problem", None) or str(exc)
        raise ConfigError(f"{_at(str(path), getattr(exc, 'problem_mark', None))}: YAML error: {problem}") from None
    if data is None:
        return {}
    if not isinstance(data, dict):
        raise ConfigError(f"{path}: a config must be a mapping, got {type(data).__name__}")
    return data
