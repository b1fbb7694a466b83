"""Tracker configs: YAML files with inheritance, dotted overrides and validation.

A config names one component per slot (``features`` is a list) plus the tracker's geometry::

    name: dr2track
    base: strcf.yaml            # optional: inherit, then override (mappings merge, lists replace)
    tracker: {search_area_scale: 5, cell_size: 4, ...}
    features: [{name: gray}, {name: fhog}, {name: colornames}]
    label: {name: distractor_repressed, top_n: 30, mu: 0.25}
    regularizers: {spatial: {name: box}, temporal: {name: temporal, theta: 12}}
    solver: {name: admm_strcf, iterations: 4}
    search: {name: motion_aware}
    scale: {name: dsst}

Overrides are dotted keys (``label.mu=0.3``, ``features.0.name=gray``); a value ``null``
removes an optional slot (``regularizers.temporal=null``; ``regularizers=null`` both roles).
Naming another component (``label.name=gaussian``, or ``label: {name: gaussian}`` in a child
file) drops the old component's parameters. ``base`` cannot be overridden: it is read with
the file.
"""
from __future__ import annotations

import copy
import dataclasses
import os
from pathlib import Path
from typing import Any, Mapping

import yaml

from dcfkit.errors import ConfigError, DcfkitError, clip, shown
from dcfkit.params import closest, param, parse_params
from dcfkit.registry import get_registry

SLOTS = ("features", "label", "regularizers", "solver", "search", "scale")
KINDS = ("feature", "label", "regularizer", "solver", "search", "scale")  # of the components each slot takes
TOP_LEVEL = ("name", "description", "base", "tracker") + SLOTS
REGULARIZER_ROLES = ("spatial", "temporal")

# Bounds on what a config, an ablation spec or a --set value may be, far beyond any real one
# (the shipped configs and specs: at most 6.4 KB, 409 values, 5 levels). Read when used: a
# program that needs more sets e.g. ``dcfkit.config.MAX_VALUES = 10**6`` before loading.
MAX_YAML_BYTES = 256 * 1024  # a YAML file or --set value (PyYAML takes up to 0.3 s to read that here)
MAX_VALUES = 10_000  # mappings, lists, keys and scalars in one document or value, an alias counted at each use
MAX_TEXT = 1024 * 1024  # characters of the scalars in one document or value, an alias counted at each use
MAX_DEPTH = 32  # levels of mappings and lists nested in one another
MAX_BASE_CHAIN = 32  # files in one 'base:' chain
DEEP = "nested more than {} levels deep (dcfkit.config.MAX_DEPTH)"
LARGE = "more than {} values, each alias counted as the values it stands for (dcfkit.config.MAX_VALUES)"
LONG = "more than {} characters, each alias counted as the text it stands for (dcfkit.config.MAX_TEXT)"


def shipped_config_dir() -> Path:
    """The shipped configs: ``configs/`` of a checkout, or ``dcfkit/configs`` when installed."""
    package = Path(__file__).resolve().parents[1]
    checkout = package.parent / "configs"
    return checkout if (checkout / "dr2track.yaml").is_file() else package / "configs"


@dataclasses.dataclass(frozen=True)
class TrackerParams:
    """Geometry of the search area and of the label (STRCF's init_size)."""

    # upper bounds: far beyond any tracker's, where patches stop fitting in memory
    search_area_scale: float = param(5.0, "search area side / sqrt(target area) ('square') or per axis", ge=1, le=50)
    search_area_shape: str = param("square", "'square' (5√(WH) square) or 'proportional' (5W x 5H)",
                                   choices=("square", "proportional"))
    min_image_sample_size: float = param(150.0**2, "smallest area (px²) of the resampled search patch",
                                         ge=8**2, le=2000**2)
    max_image_sample_size: float = param(200.0**2, "largest area (px²) of the resampled search patch",
                                         ge=8**2, le=2000**2)
    cell_size: int = param(4, "feature cell size in pixels", ge=1, le=64)
    output_sigma_factor: float = param(1 / 16, "label σ as a fraction of sqrt(target area in cells)", gt=0)
    fft_backend: str = param("scipy", "FFT implementation", choices=("scipy", "pyfftw"))
    training_sample: str = param("extract", "'extract' m^t at p^t (Algorithm 1) or 'shift' the detection sample "
                                 "to p^t in the Fourier domain, as DR²Track's code (by the translation over the "
                                 "scale after the scale update; one extraction less)",
                                 choices=("extract", "shift"))
    init_position: str = param("exact", "'exact': the box's centre x + (w-1)/2; 'whole_pixel': the authors' BACF and "
                               "DR²Track, centre floor(x + floor(w/2)) and size floor(w) (1-based)",
                               choices=("exact", "whole_pixel"))
    sampling: str = param("subpixel", "'subpixel': the search region around the exact centre, area-averaged and "
                          "bilinearly mapped onto the sample grid; 'whole_pixel': the authors' get_pixels, whole "
                          "pixels around round(centre), then OpenCV's resize (bilinear when the width grows, else "
                          "area)", choices=("subpixel", "whole_pixel"))
    window: str = param("hann_interior", "cosine window of the features: 'hann_interior' hann(n+2) without its zero "
                        "ends (DR²Track's code), 'hann' hann(n) with them (STRCF's and BACF's)",
                        choices=("hann_interior", "hann"))
    peak: str = param("bounded_newton", "sub-cell peak: 'bounded_newton' Newton steps kept within the grid maximum's "
                      "cell, the scale with the highest grid value; 'newton' the authors' resp_newton (unbounded "
                      "steps, the scale with the highest refined value)", choices=("bounded_newton", "newton"))
    translation: str = param("exact", "'exact', or 'whole_pixel': the displacement rounded to whole image pixels "
                             "(BACF's and DR²Track's translation_vec)", choices=("exact", "whole_pixel"))
    clamp_position: bool = param(True, "keep the target centre on the image (the authors' codes do not)")
    box_output: str = param("exact", "the reported box: 'exact' x = cx - (w-1)/2 with the exact size; "
                            "'rounded' the same rounded to whole 1-based pixels (STRCF's report_tracking_result); "
                            "'half_size' x = cx - w/2 with the size rounded (DR²Track's rect_position); "
                            "'floor_half' x = cx - floor(w/2) with the size floored (BACF's)",
                            choices=("exact", "rounded", "half_size", "floor_half"))
    newton_iterations: int = param(5, "Newton steps refining the response peak", ge=0, le=100)
    cell_selection_thresh: float = param(0.0, "BACF's small-target rule: if the search area holds fewer than this "
                                         "fraction of max_image_sample_size / cell_size² cells, use cells of "
                                         "ceil(sqrt(area / (fraction x that many))) pixels instead (0: off)",
                                         ge=0, le=1)
    blank_std: float = param(1.0, "a frame whose pixel values vary less than this (standard deviation, RMS over "
                             "colour channels) is a dropped frame: the box is held, nothing is learnt (0: off); "
                             "the first frame's search area must vary at least this much", ge=0)

    def validate(self):
        """min_image_sample_size <= max_image_sample_size."""
        if self.min_image_sample_size > self.max_image_sample_size:
            return "need min_image_sample_size <= max_image_sample_size"


class _OverLimit(Exception):
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
    """Raise :class:`_OverLimit` if ``root`` nests deeper than MAX_DEPTH, holds more than
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
            raise _OverLimit("contains itself (an alias inside its own anchor)", path, item)
        values, characters, height = known[id(item)]
        if len(path) + height > MAX_DEPTH:
            raise _OverLimit(DEEP.format(MAX_DEPTH), path, item)
        return values, characters, height

    def add_up(item: Any, children: list) -> tuple[int, int, int]:
        if len(path) >= MAX_DEPTH:
            raise _OverLimit(DEEP.format(MAX_DEPTH), path, item)
        values, characters, height = 1, 0, 0
        for key, child in children:
            path.append(key)
            more, longer, below = visit(child)
            path.pop()
            values, characters, height = values + more, characters + longer, max(height, below + 1)
            if values > MAX_VALUES:
                raise _OverLimit(LARGE.format(MAX_VALUES), path, item)
            if characters > MAX_TEXT:
                raise _OverLimit(LONG.format(MAX_TEXT), path, item)
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
    except _OverLimit as exc:
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
                raise _OverLimit(DEEP.format(MAX_DEPTH), [], self.peek_event())
            if self._nodes > MAX_VALUES:
                raise _OverLimit(LARGE.format(MAX_VALUES), [], self.peek_event())
            return super().compose_node(parent, index)
        finally:
            self._depth -= 1

    def get_single_data(self):
        node = self.get_single_node()
        if node is None:
            return None
        _measure(node, _node_items)
        return _tree(self.construct_document(node))

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


def _tree(value: Any) -> Any:
    """``value`` with its mappings and lists unshared: an alias is a copy, so that an override
    changes the one place it names (called on measured values only: bounded depth and size)."""
    if isinstance(value, dict):
        return {k: _tree(v) for k, v in value.items()}
    if isinstance(value, list):
        return [_tree(v) for v in value]
    return value


def _load_yaml(text: str) -> Any:
    """``text`` read by :class:`_BoundedLoader`: raises yaml.YAMLError (not YAML) or :class:`_OverLimit`."""
    if len(text) > MAX_YAML_BYTES:
        raise _OverLimit(f"longer than {MAX_YAML_BYTES} characters (dcfkit.config.MAX_YAML_BYTES)", [])
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
        raise ConfigError(f"{path}: larger than {MAX_YAML_BYTES} bytes (dcfkit.config.MAX_YAML_BYTES); "
                          f"is it a config?")
    try:
        data = _load_yaml(raw.decode("utf-8"))
    except UnicodeDecodeError as exc:
        raise ConfigError(f"{path}: not a UTF-8 text file (byte {exc.start} is not UTF-8)") from None
    except _OverLimit as exc:
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


def merge(base: Mapping, override: Mapping) -> dict:
    """Deep merge: mappings merge key by key, anything else (lists included) is replaced.

    A component mapping that names a different component replaces the old one whole (its
    parameters would not fit the new component)."""
    out = copy.deepcopy(dict(base))
    for key, value in override.items():
        if isinstance(value, Mapping) and isinstance(out.get(key), Mapping) and \
                value.get("name", out[key].get("name")) == out[key].get("name"):
            out[key] = merge(out[key], value)
        else:
            out[key] = copy.deepcopy(value)
    return out


def _load_file(path: Path, chain: tuple[Path, ...] = ()) -> tuple[dict, tuple[Path, ...]]:
    """The file merged over its ``base`` chain, and the files read (this one first)."""
    path = path.resolve()
    if path in chain:
        raise ConfigError(f"{path}: circular 'base' chain: {' -> '.join(map(str, chain + (path,)))}")
    if len(chain) >= MAX_BASE_CHAIN:  # each file is a level of recursion here and in merge()
        raise ConfigError(f"{chain[0]}: the 'base' chain is longer than {MAX_BASE_CHAIN} files "
                          f"(dcfkit.config.MAX_BASE_CHAIN): {chain[0]} -> {chain[1]} -> ... -> {path}")
    data = read_yaml(path)
    base = data.pop("base", None)
    if base is None:
        return data, (path,)
    if not isinstance(base, str):
        raise ConfigError(f"{path}: 'base' must be a file name, got {shown(base)}")
    base_path = path.parent / base
    if not os.path.isfile(base_path):  # a shipped config by name ('dr2track' or 'dr2track.yaml')
        shipped = shipped_config(base) if Path(base).name == base else None
        if shipped is None:
            raise ConfigError(f"{path}: base config '{clip(base)}' not found (looked for {clip(str(base_path))} "
                              f"and for a shipped config of that name)")
        base_path = shipped
    inherited, files = _load_file(base_path, chain + (path,))
    return merge(inherited, data), (path,) + files


def parse_value(text: str, where: str = "--set value") -> Any:
    """A CLI override value: YAML scalars/lists ('0.3', 'true', '[1, 2]', 'null'); text that is
    not YAML stays text. A value over the bounds of a config is a ConfigError naming ``where``."""
    try:
        return _load_yaml(text)
    except _OverLimit as exc:
        raise ConfigError(f"{where}: {exc.describe()}") from None
    except yaml.YAMLError:
        return text


def parse_overrides(items) -> dict:
    """``["label.mu=0.3", "name=x"]`` -> ``{"label.mu": 0.3, "name": "x"}`` (CLI ``--set`` values)."""
    out = {}
    for item in items or ():
        key, sep, value = item.partition("=")
        if not sep or not key.strip():
            raise ConfigError(f"--set expects KEY=VALUE (e.g. label.mu=0.3), got {shown(item)}")
        out[key.strip()] = parse_value(value, f"--set {clip(key.strip())}") if value.strip() else ""
    return out


def set_dotted(config: dict, key: str, value: Any) -> None:
    """Set ``a.b.0.c`` in nested dicts/lists; list indices are integers."""
    parts = key.split(".")
    node: Any = config
    for i, part in enumerate(parts[:-1]):
        if isinstance(node, list):
            node = node[_index(node, part, ".".join(parts[: i + 1]))]
        elif isinstance(node, dict):
            if not isinstance(node.get(part), (dict, list)):
                node[part] = {}
            node = node[part]
        else:
            raise ConfigError(f"override '{clip(key)}': '{clip('.'.join(parts[: i + 1]))}' is not a mapping")
    last = parts[-1]
    if isinstance(node, list):
        node[_index(node, last, key)] = value
    else:
        if last == "name" and len(parts) > 1 and node.get("name") not in (None, value):
            node.clear()  # another component: the old one's parameters do not apply
        node[last] = value


def _index(items: list, part: str, where: str) -> int:
    try:
        i = int(part)
    except ValueError:
        raise ConfigError(f"override '{clip(where)}': this is a list; use an index 0..{len(items) - 1}") from None
    if not -len(items) <= i < len(items):
        raise ConfigError(f"override '{clip(where)}': index {shown(i)} out of range 0..{len(items) - 1}")
    return i


def load_config(source: str | Path | Mapping, overrides: Mapping[str, Any] | None = None) -> dict:
    """Read a config (path, or a dict), apply dotted overrides, validate, fill in defaults.

    A bare name such as 'dr2track' finds ``configs/dr2track.yaml``. Returns the fully
    resolved config: every component with all its parameters. An error in a config with a
    ``base`` lists the files it was merged from (the key may sit in any of them).
    """
    files: tuple[Path, ...] = ()
    if not isinstance(source, (str, os.PathLike, Mapping)):
        raise ConfigError(f"a config is a file path, a shipped config name or a mapping, got {type(source).__name__}")
    if isinstance(source, Mapping):
        origin = "<config dict>"
        check_value(source, origin)  # before deepcopy and merge walk it
        data = _tree(copy.deepcopy(dict(source)))
        base = data.pop("base", None)
        if base is not None:
            if not isinstance(base, (str, os.PathLike)):
                raise ConfigError(f"{origin}: 'base' must be a file name, got {shown(base)}")
            inherited, files = _load_file(_find(base))
            data = merge(inherited, data)
    else:
        path = _find(source)
        data, files = _load_file(path)
        origin = str(path)
    for key, value in (overrides or {}).items():
        if not isinstance(key, str):
            raise ConfigError(f"override keys are dotted strings such as 'label.mu', got {shown(key)}")
        if key.split(".")[0].strip() == "base":  # set_dotted would set a key that nothing reads any more
            raise ConfigError(f"override '{clip(key)}': a config's base is read with its file, before overrides "
                              f"apply; give that config instead (its shipped name or file), or write a file whose "
                              f"base: names it")
        check_value(value, f"override '{clip(key)}'")
        set_dotted(data, key, value)
    check_value(data, origin)  # dotted keys nest values deeper; merged files add up
    try:
        return resolve(data, origin)
    except DcfkitError as exc:
        chain = [origin] * isinstance(source, Mapping) + [str(f) for f in files]
        if len(chain) < 2:
            raise
        raise type(exc)(f"{exc} (config merged from {' <- '.join(chain)})") from None


def components(config: Mapping) -> list[tuple[str, str]]:
    """The ``(kind, name)`` of every component a resolved config uses."""
    def name(spec):
        return spec.get("name") if isinstance(spec, Mapping) else None

    features, regularizers = config.get("features"), config.get("regularizers")
    found = [("feature", name(f)) for f in features] if isinstance(features, (list, tuple)) else []
    found += [("regularizer", name(r)) for r in regularizers.values()] if isinstance(regularizers, Mapping) else []
    found += [(kind, name(config.get(slot))) for kind, slot in
              (("label", "label"), ("solver", "solver"), ("search", "search"), ("scale", "scale"))]
    return [(kind, n) for kind, n in found if isinstance(n, str)]


def shipped_config(name: str | Path) -> Path | None:
    """The shipped config called ``name`` ('dr2track' or 'dr2track.yaml'), or None."""
    folder = shipped_config_dir()
    return next((c for c in (folder / name, folder / f"{name}.yaml") if os.path.isfile(c)), None)


def _find(source: str | Path) -> Path:
    path = Path(source)
    if os.path.isfile(path):  # os.path: a name too long for the file system is no file (Path.is_file raises)
        return path
    found = shipped_config(path)
    if found is not None:
        return found
    folder = shipped_config_dir()
    shipped = sorted(p.stem for p in folder.glob("*.yaml")) if folder.is_dir() else []
    raise ConfigError(f"config not found: {clip(str(source))}"
                      + (f"; shipped configs: {', '.join(shipped)}" if shipped else ""))


def _component(registry, kind: str, spec: Any, where: str) -> dict:
    instance = registry.build(kind, spec, where)
    return {"name": type(instance).name, **dataclasses.asdict(instance.params)}


def resolve(data: Mapping, origin: str) -> dict:
    """Validate every key of ``data`` and return it with all defaults filled in."""
    registry = get_registry()
    unknown = [k for k in data if k not in TOP_LEVEL]
    if unknown:
        raise ConfigError(f"{origin}: unknown key {shown(unknown[0])}{closest(unknown[0], TOP_LEVEL)}; "
                          f"valid keys: {', '.join(TOP_LEVEL)}")
    missing = [k for k in ("features", "label", "solver") if k not in data]
    if missing:
        raise ConfigError(f"{origin}: missing required key '{missing[0]}'")
    for key in ("name", "description"):
        if data.get(key) is not None and not isinstance(data[key], str):
            raise ConfigError(f"{origin}: {key}: expected a string, got {shown(data[key])}")
    out: dict[str, Any] = {"name": data.get("name") or Path(origin).stem}
    if data.get("description"):
        out["description"] = str(data["description"])
    tracker = parse_params(TrackerParams, data.get("tracker"), f"{origin}: tracker")
    out["tracker"] = dataclasses.asdict(tracker)
    features = data["features"]
    if not isinstance(features, list) or not features:
        raise ConfigError(f"{origin}: features must be a non-empty list, e.g. [{{name: fhog}}]")
    out["features"] = [_component(registry, "feature", f, f"{origin}: features[{i}]") for i, f in enumerate(features)]
    out["label"] = _component(registry, "label", data["label"], f"{origin}: label")
    regs = data.get("regularizers")
    regs = {} if regs is None else regs  # not `or {}`: [], '' or false stood for "none" unnoticed
    if not isinstance(regs, Mapping):
        raise ConfigError(f"{origin}: regularizers: expected a mapping of roles ({', '.join(REGULARIZER_ROLES)}) to "
                          f"components, got {shown(regs)} (null: none; regularizers.temporal: null drops one role)")
    out["regularizers"] = {}
    for role in regs:
        if role not in REGULARIZER_ROLES:
            raise ConfigError(f"{origin}: regularizers.{clip(str(role))}: unknown role"
                              f"{closest(role, REGULARIZER_ROLES)}; valid: {', '.join(REGULARIZER_ROLES)}")
    for role in REGULARIZER_ROLES:
        spec = regs.get(role)
        if spec is None:
            out["regularizers"][role] = None
            continue
        where = f"{origin}: regularizers.{role}"
        resolved = _component(registry, "regularizer", spec, where)
        cls = registry.entry("regularizer", resolved["name"]).cls
        if getattr(cls, "role", None) != role:
            valid = [n for n in registry.names("regularizer")
                     if getattr(registry.entry("regularizer", n).cls, "role", None) == role]
            raise ConfigError(f"{where}: '{resolved['name']}' is a {getattr(cls, 'role', '?')} regularizer; "
                              f"{role} ones: {', '.join(valid)}")
        out["regularizers"][role] = resolved
    out["solver"] = _component(registry, "solver", data["solver"], f"{origin}: solver")
    out["search"] = _component(registry, "search", data.get("search", "fixed"), f"{origin}: search")
    out["scale"] = _component(registry, "scale", data.get("scale", "pyramid"), f"{origin}: scale")
    return out
