"""The component contracts (docs/plugins.md, section 5): what registration checks, what the
tracker calls (a reset of every component at each init), and that every parameter value a
built-in component accepts tracks: a value is refused at load (a ConfigError naming it) or
tracks with finite boxes, never a raw numpy/Python exception, an error on a later frame or
a NaN box."""
import dataclasses
import functools
import typing

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

import dcfkit
from dcfkit import registry as reg
from dcfkit.components.base import Target, base_of, contract_problems
from dcfkit.components.features.base import Feature
from dcfkit.components.labels.base import Label
from dcfkit.components.regularizers import SpatialRegularizer, TemporalRegularizer
from dcfkit.components.search.base import Search
from dcfkit.components.solvers import Solver
from dcfkit.config.slots import KINDS
from dcfkit.datasets.synthetic import make_sequence
from dcfkit.errors import ConfigError, DcfkitError, RegistryError
from dcfkit.params import param
from dcfkit.registry import Component


@functools.lru_cache(maxsize=1)
def tiny_sequence():
    """3 frames of 48x64 pixels, an 8x10 target that stays in view: tracking them takes milliseconds."""
    seq = make_sequence(n_frames=100, size=(48, 64), target=(8, 10), distractor=False, speed=1.0, seed=1)
    return dataclasses.replace(seq, frames=seq.frames[:3], ground_truth=seq.ground_truth[:3])


# every slot filled, with a 32x32-pixel search patch (8x8 cells): the component under test replaces one
TINY = {"name": "tiny", "tracker": {"min_image_sample_size": 32**2, "max_image_sample_size": 32**2},
        "features": [{"name": "gray"}], "label": {"name": "gaussian"},
        "regularizers": {"spatial": {"name": "box"}, "temporal": {"name": "temporal"}},
        "solver": {"name": "admm_strcf"}, "search": {"name": "motion_aware"}, "scale": {"name": "pyramid", "n_scales": 3}}


def slot_override(kind: str, cls: type, params: dict) -> dict:
    """``load_tracker`` overrides that put component ``cls`` with ``params`` into its slot of TINY."""
    spec = {"name": cls.name, **params}
    if kind == "feature":
        return {"features": [spec]}
    if kind == "regularizer":
        return {f"regularizers.{cls.role}": spec}
    if kind == "memory" or getattr(cls, "loop", None) == "continuous":  # ECO's: one feature block, a memory
        solver = spec if kind == "solver" else {"name": "eco"}
        solver = {"cell_sizes": (4,), "compressed_dims": (1,), **solver}
        return {"solver": solver, "memory": spec if kind == "memory" else {"name": "gmm"},
                "regularizers.spatial": None, "regularizers.temporal": None}
    if kind == "solver":  # without the regularizers it has no term for (KCF's, DSST's), which the tracker refuses
        return {kind: spec, **{f"regularizers.{role}": None for role in ("spatial", "temporal") if role not in cls.terms}}
    if kind == "redetect" or getattr(cls, "needs_reliability", False):  # they act on a reliability's verdicts
        return {kind: spec, "reliability": {"name": "lmcf"}}
    return {kind: spec}


FLOATS = [0.0, -0.0, 5e-324, 7.8e-307, 1e-300, 1e-30, 1e-10, 1e-6, 0.5, 1.0, 1.5, 2.0, 10.0, 1e6, 1e10, 1e30,
          1e300, 1.7976931348623157e308, -1e-300, -1.0, -1e300]
INTS = [0, 1, 2, 3, 4, 5, -1, 2**31, 2**63, 10**12, -(10**12), 10**100]
PATHS = ["", "~0/table.npy", "missing.npy", "table.txt", "a\x00b.npy", "x" * 5000 + ".npy"]


def values_of(field: dataclasses.Field, annotation) -> st.SearchStrategy:
    """Values of a ``Params`` field's declared type, extremes included."""
    if field.metadata.get("choices"):
        return st.sampled_from(field.metadata["choices"])
    if annotation is bool:
        return st.booleans()
    if annotation is int:
        return st.one_of(st.sampled_from(INTS), st.integers(-5, 120))
    if annotation is float:
        return st.one_of(st.sampled_from(FLOATS), st.floats(allow_nan=False, allow_infinity=False),
                         st.floats(-100, 100))
    if annotation is str:
        return st.one_of(st.sampled_from(PATHS), st.text(max_size=12))
    if typing.get_origin(annotation) is tuple:  # tuple[X, ...]: a few of X's values
        item = values_of(dataclasses.field(), typing.get_args(annotation)[0])
        return st.lists(item, max_size=3).map(tuple)
    raise AssertionError(f"no strategy for {annotation!r}: add one (the built-ins' Params grew a new type)")


def params_of(cls: type) -> st.SearchStrategy:
    """One to three of ``cls``'s parameters, each with a value of its declared type (few at a
    time: an extreme value must often be the only one, or another one's refusal hides it)."""
    hints = typing.get_type_hints(cls.Params)
    fields = {f.name: values_of(f, hints[f.name]) for f in dataclasses.fields(cls.Params)}
    if not fields:
        return st.just({})
    names = st.lists(st.sampled_from(sorted(fields)), min_size=1, max_size=3, unique=True)
    return names.flatmap(lambda chosen: st.fixed_dictionaries({name: fields[name] for name in chosen}))


def builtins(with_params: bool = False) -> list[tuple[str, type]]:
    """(kind, class) of every built-in component (``with_params``: those that have parameters)."""
    registry = reg.build_registry(external=False)
    found = [(kind, registry.entry(kind, name).cls) for kind in KINDS for name in registry.names(kind)]
    return [(kind, cls) for kind, cls in found if dataclasses.fields(cls.Params) or not with_params]


def track_tiny(overrides: dict) -> str:
    """'refused' (a ConfigError at load) or 'tracked' (3 frames, finite boxes); a dcfkit error
    while tracking fails the test with its message, anything else propagates."""
    try:
        tracker = dcfkit.load_tracker(TINY, overrides=overrides)
    except ConfigError:
        return "refused"
    seq = tiny_sequence()
    try:
        tracker.init(seq.frames[0], seq.ground_truth[0])
        boxes = [tracker.update(frame) for frame in seq.frames[1:]]
    except DcfkitError as exc:
        pytest.fail(f"{overrides} passed validation, then: {type(exc).__name__}: {exc}")
    assert np.isfinite(boxes).all(), f"{overrides}: boxes {boxes}"
    return "tracked"


@pytest.mark.parametrize("kind, cls", builtins(with_params=True), ids=lambda v: getattr(v, "name", v))
@given(data=st.data())
def test_every_accepted_parameter_value_tracks(kind, cls, data):
    """No ZeroDivisionError, OverflowError, MemoryError, numpy ValueError... and no NaN box,
    whatever values of their declared types the parameters get; nor a dcfkit error on the
    way (a TrackingError 'the filter overflowed'): a value that cannot work is refused at load."""
    track_tiny(slot_override(kind, cls, data.draw(params_of(cls), label="params")))


@pytest.mark.parametrize("kind, cls, params, key", [
    ("solver", "admm_strcf", {"beta": 1e-300}, "beta"),            # γ underflowed to 0: ZeroDivisionError
    ("solver", "admm_strcf", {"beta": 7.8e-307, "iterations": 3}, "beta"),
    ("solver", "admm_strcf", {"beta": 0.5, "iterations": 10000}, "beta"),
    ("solver", "admm_bacf", {"gamma0": 1e-300}, "gamma0"),        # a NaN filter
    ("solver", "admm_strcf", {"gamma_max": 1e-30}, "gamma_max"),
    ("solver", "admm_strcf", {"h_step": "authors", "iterations": 8}, "h_step 'authors'"),  # the filter overflowed
    ("regularizer", "temporal", {"theta": 1e300}, "theta"),       # θ·v̂ˡ overflows float32
    ("regularizer", "box", {"outside": 1e300}, "outside"),         # w² overflows
    ("regularizer", "smooth", {"minimum": 1.0, "edge": 1.0, "power": 1e300}, "power"),  # 0 · inf = NaN
    ("regularizer", "crop", {"lam": 1e300}, "lam"),
    ("label", "distractor_repressed", {"mu": 1e300}, "mu"),       # y = -inf
    ("label", "distractor_repressed", {"neighbourhood": 10**6 + 1}, "neighbourhood"),  # a padded copy: MemoryError
    ("feature", "fhog", {"n_orients": 10**12}, "n_orients"),      # MemoryError
    ("feature", "colornames", {"table_path": "~0/table.npy"}, "table_path"),  # RuntimeError from pathlib
    ("feature", "colornames", {"table_path": "missing.npy"}, "table_path"),   # found missing at frame 1
    ("search", "motion_aware", {"gain": 1e30}, "gain"),           # IndexError with clamp_position false
    ("scale", "dsst", {"lam": 0.0}, "lam"),                       # 0/0 on a featureless scale sample
    ("solver", "kernel_ridge", {"lam": 0.0}, "lam"),               # ŷ / 0 where k̂^{xx} is 0
    ("solver", "kernel_ridge", {"sigma": 1e-300}, "sigma"),        # σ² underflows: 0/0 at the peak
    ("solver", "ridge", {"lam": 0.0}, "lam"),                      # 0/0 on a featureless sample
    ("scale", "dsst", {"sigma_factor": 1e300}, "sigma_factor"),   # a flat scale label
])
def test_values_that_cannot_work_are_refused_at_load_naming_the_key(kind, cls, params, key):
    cls = reg.build_registry(external=False).entry(kind, cls).cls
    with pytest.raises(ConfigError, match=rf"\({kind} '{cls.name}'\): .*{key}"):
        dcfkit.load_tracker(TINY, overrides=slot_override(kind, cls, params))


@pytest.mark.parametrize("lam", [5e-324, 1e-320, 2.2e-308, 1e-300, 9.9e-11])
def test_a_dsst_lam_under_its_floor_is_refused_naming_it(lam):
    """λ divides the scale filter's response (by Σ|x̂|² + λ, λ alone where the samples have no
    energy): subnormal values such as 1e-320 were accepted. The floor is the ADMM penalty's."""
    with pytest.raises(ConfigError, match=r"scale \(scale 'dsst'\): lam must be in \[1e-10, 1e\+10\], got "):
        dcfkit.load_tracker(TINY, overrides={"scale": {"name": "dsst", "lam": lam}})


def test_a_dsst_lam_at_its_floor_tracks():
    assert track_tiny({"scale": {"name": "dsst", "lam": 1e-10}}) == "tracked"


def test_a_dsst_working_patch_over_the_sample_budget_is_refused_naming_its_keys():
    """The budget is the tracker's (``$DCFKIT_MAX_SAMPLE_PIXELS``): registering the built-ins
    never depends on the environment."""
    with pytest.raises(ConfigError, match=r"scale.n_scales 101 samples of scale.model_max_area .*DCFKIT_MAX_SAMPLE"):
        dcfkit.load_tracker(TINY, overrides={"scale": {"name": "dsst", "model_max_area": 10000, "n_scales": 101,
                                                       "step": 1.047}})


@pytest.mark.parametrize("kind, cls", builtins(), ids=lambda v: getattr(v, "name", v))
def test_the_defaults_of_every_builtin_track(kind, cls):
    assert track_tiny(slot_override(kind, cls, {})) == "tracked"


# -- what init resets ------------------------------------------------------------------------
class Remembering(Label):
    """A label that counts the frames it made since its last reset."""

    name = "remembering"

    def reset(self):
        self.made = 0

    def make(self, g, detection):
        self.made += 1
        return g, np.zeros((0, 2), int)


class CountingFeature(Feature):
    """A constant feature that counts its extractions since its last reset."""

    name = "counting"

    def reset(self):
        self.extracted = 0

    def channels(self):
        return 1

    def extract(self, patch, cell_size):
        self.extracted += 1
        return np.ones((1, patch.shape[0] // cell_size, patch.shape[1] // cell_size), np.float32)


def test_init_resets_labels_and_features_for_the_new_target():
    """A tracker re-initialised on another target starts every component afresh: the label
    and features too (they used to keep their state: only the solver and search were reset)."""
    seq = tiny_sequence()
    tracker = dcfkit.load_tracker(TINY, overrides={"scale.n_scales": 1})
    tracker.label = Remembering()
    tracker.features.append(CountingFeature())
    tracker.label.made = tracker.features[-1].extracted = 100  # left over from an earlier target
    tracker.init(seq.frames[0], seq.ground_truth[0])
    assert tracker.label.made == 1 and tracker.features[-1].extracted == 1
    tracker.update(seq.frames[1])
    assert tracker.label.made == 2 and tracker.features[-1].extracted == 3  # the search and the training sample
    tracker.init(seq.frames[2], seq.ground_truth[2])
    assert tracker.label.made == 1 and tracker.features[-1].extracted == 1


# -- what registration checks ----------------------------------------------------------------
def _component(base: type, name: str, **members) -> type:
    return type(f"Test_{name}", (base,), {"name": name, **members})


def _make(self, g, detection):
    return g, np.zeros((0, 2), int)


@dataclasses.dataclass(frozen=True)
class ThetaParams:
    theta: float = param(1.0, "θ")


@dataclasses.dataclass(frozen=True)
class IntThetaParams:
    theta: int = param(1, "θ as a count")


@pytest.mark.parametrize("cls, message", [
    (_component(Label, "no_make"), r"label 'no_make' \(from \?\): it does not implement make\(g, detection\)"),
    (_component(Label, "short_make", make=lambda self, g: g),
     r"make\(self, g\) cannot be called as make\(self, g, detection\) \(the tracker passes 2 arguments\)"),
    (_component(Label, "long_make", make=lambda self, g, d, extra: g), r"cannot be called as make\(self, g, detection\)"),
    (_component(Label, "static_make", make=staticmethod(lambda g: g)), r"make\(g\) cannot be called as make\(g, detection\)"),
    (_component(Label, "make_attribute", make=3), r"make is not a method"),
    (_component(Label, "bad_reset", make=_make, reset=lambda self, target: None),
     r"reset\(self, target\) cannot be called as reset\(self\)"),
    (_component(Component, "unbased", kind="label", make=_make), r"a label must subclass dcfkit.components.labels.Label"),
    (_component(Component, "unbased_reg", kind="regularizer", role="temporal", Params=ThetaParams),
     r"must subclass dcfkit.components.regularizers.SpatialRegularizer or dcfkit.components.regularizers.TemporalRegularizer"),
    (_component(TemporalRegularizer, "no_theta"), r"its Params has no float field 'theta'"),
    (_component(TemporalRegularizer, "int_theta", Params=IntThetaParams), r"its Params has no float field 'theta'"),
    (_component(SpatialRegularizer, "no_weights"), r"it does not implement weights_squared\(shape, target_cells\)"),
    (_component(SpatialRegularizer, "temporal_role", role="temporal", weights_squared=lambda self, s, t: None),
     r"role 'temporal' is not its base class SpatialRegularizer's \('spatial'\)"),
    (_component(Solver, "no_train", reset=lambda self: None), r"it does not implement train\(xf, yf, w2, theta, fft\)"),
    (_component(Feature, "no_channels", extract=lambda self, p, c: p), r"it does not implement channels\(\)"),
    (_component(Search, "bad_observe", observe=lambda self: None), r"observe\(self\) cannot be called as observe\(self, position\)"),
])
def test_registration_refuses_a_component_that_breaks_its_contract(cls, message):
    with pytest.raises(RegistryError, match=message):
        reg.Registry().register(cls)


def _wrapped(fn):
    """A decorator as a plugin may write one: a ``functools.wraps`` wrapper taking ``*args``."""
    @functools.wraps(fn)
    def wrapper(self, *args, **kwargs):
        return fn(self, *args, **kwargs)
    return wrapper


class CachedFeature(Feature):
    """A constant feature: channels() cached with functools.lru_cache, extract() wrapped."""

    name = "cached_constant"

    @functools.lru_cache(maxsize=None)
    def channels(self):
        return 1

    @_wrapped
    def extract(self, patch, cell_size):
        return np.ones((1, patch.shape[0] // cell_size, patch.shape[1] // cell_size), np.float32)


class PartialLabel(Label):
    """The Gaussian label as it comes: make() a functools.partialmethod of a more general method."""

    name = "partial_gaussian"

    def _make(self, repress: bool, g, detection):
        return g, np.zeros((0, 2), int)

    make = functools.partialmethod(_make, False)

    @functools.lru_cache(maxsize=None)
    def reset(self):
        pass


class WrappedSearch(Search):
    """The fixed search, with observe() wrapped and centre() a partialmethod taking a keyword."""

    name = "wrapped_search"

    @_wrapped
    def observe(self, position):
        super().observe(position)

    def _centre(self, shift=0.0):
        return Search.centre(self)

    centre = functools.partialmethod(_centre, shift=0.0)


@pytest.mark.parametrize("kind, cls", [("feature", CachedFeature), ("label", PartialLabel),
                                       ("search", WrappedSearch)], ids=lambda v: getattr(v, "name", v))
def test_decorated_methods_meet_the_contract_and_track(kind, cls, monkeypatch):
    """lru_cache, partialmethod and functools.wraps methods used to be refused at registration
    (the check did not bind them to an instance as Python does)."""
    registry = reg.build_registry(external=False)
    registry.register(cls)
    monkeypatch.setattr(reg, "_REGISTRY", registry)
    assert track_tiny(slot_override(kind, cls, {})) == "tracked"


def _short_make(self, g):
    return g, np.zeros((0, 2), int)


def _make3(self, a, b, g, detection=None):
    return g, np.zeros((0, 2), int)


@pytest.mark.parametrize("members, message", [
    ({"make": functools.lru_cache(maxsize=None)(_short_make)},
     r"make\(self, g\) cannot be called as make\(self, g, detection\) \(the tracker passes 2 arguments\)"),
    ({"make": _wrapped(_short_make)}, r"make\(self, g\) cannot be called as make\(self, g, detection\)"),
    ({"make": functools.partialmethod(_make3, 1, 2, 3)}, r"make\(detection=None\) cannot be called as "
                                                          r"make\(g, detection\)"),
    ({"make": functools.partialmethod(_make3, 1, 2, 3, 4)}, r"make\(\) cannot be called as make\(g, detection\)"),
    ({"make": _make, "reset": functools.partialmethod(_make3, 1)}, r"reset\(b, g, detection=None\) cannot be called as "
                                                                   r"reset\(\)"),
])
def test_decorated_methods_that_break_the_contract_are_still_refused(members, message):
    with pytest.raises(RegistryError, match=message):
        reg.Registry().register(_component(Label, "decorated", **members))


def test_a_temporal_regularizer_must_declare_theta_and_its_value_is_bounded():
    """The tracker reads ``params.theta`` of whichever temporal regularizer a config names (a
    plugin's without one used to fail with a raw AttributeError on the first frame), and the
    solvers need it in [0, 1e10] whichever component supplies it."""
    r = reg.Registry()
    with pytest.raises(RegistryError, match=r"regularizer 'thetaless' .*its Params has no float field 'theta' "
                                            r"\(the tracker reads params.theta, in \[0, 1e\+10\]\)"):
        r.register(_component(TemporalRegularizer, "thetaless"))
    r.register(_component(TemporalRegularizer, "plugin_theta", Params=ThetaParams))
    assert r.build("regularizer", {"name": "plugin_theta", "theta": 3}, "x: regularizers.temporal").params.theta == 3.0
    with pytest.raises(ConfigError, match=r"x: regularizers.temporal \(regularizer 'plugin_theta'\).theta: 1e\+300 "
                                          r"is outside \[0, 1e\+10\]"):
        r.build("regularizer", {"name": "plugin_theta", "theta": 1e300}, "x: regularizers.temporal")


def test_a_solver_without_params_has_none_not_the_admm_ones():
    """``Solver`` itself declared the ADMM's parameters, so a plugin solver that is not an
    ADMM accepted and silently ignored ``iterations``, ``gamma0``..."""
    r = reg.Registry()
    r.register(_component(Solver, "closed_form", reset=lambda self: None, train=lambda self, xf, yf, w2, t, fft: xf))
    assert dataclasses.fields(r.entry("solver", "closed_form").cls.Params) == ()
    with pytest.raises(ConfigError, match=r"solver 'closed_form'\): unknown parameter 'iterations'; valid parameters: none"):
        r.build("solver", {"name": "closed_form", "iterations": 4}, "x: solver")
    assert {f.name for f in dataclasses.fields(reg.build_registry(external=False).entry("solver", "admm_strcf").cls.Params)} \
        >= {"iterations", "gamma0", "beta", "gamma_max"}


def test_every_builtin_meets_its_contract():
    for kind, cls in builtins():
        base = base_of(cls, kind, cls.name)
        assert contract_problems(cls, base) == [], (kind, cls.name)


def test_a_base_class_declares_its_kind_with_a_contract(monkeypatch):
    from dcfkit.components import base  # deferred: its table of kinds is patched here

    monkeypatch.setattr(base, "_BASES", dict(base._BASES))
    with pytest.raises(TypeError, match="declares kind 'tracklet' without a Contract"):
        class NoContract(Component, declares="tracklet"):
            pass

    class Tracklet(Component, declares="tracklet"):
        contract = base.Contract(required={"step": ("x",)})

    class Mine(Tracklet):
        name = "mine"

        def step(self, x):
            return x

    assert Tracklet.kind == "tracklet" and "tracklet" in base.kinds()
    registry = reg.Registry()
    registry.register(Mine)
    assert registry.names("tracklet") == ["mine"] and registry.kinds() == ["tracklet"]
    with pytest.raises(RegistryError, match=r"a tracklet must subclass .*Tracklet"):
        registry.register(type("Loose", (Component,), {"kind": "tracklet", "name": "loose"}))


def test_the_built_registry_lists_the_kinds_in_the_order_of_the_slots():
    assert reg.get_registry().kinds() == list(KINDS)


class Sized(Label):
    """A label that needs the target's geometry on frame 1, where ``detection`` is None."""

    name = "sized"

    def start(self, target):
        self.target = target

    def make(self, g, detection):
        assert g.shape == self.target.filter_size  # start came first, with the label's grid
        return g, np.zeros((0, 2), int)


def test_every_component_gets_the_new_targets_geometry_at_init():
    seq = tiny_sequence()
    tracker = dcfkit.load_tracker(TINY, overrides={"scale.n_scales": 1})
    tracker.label = Sized()
    tracker.init(seq.frames[0], seq.ground_truth[0])
    target, g = tracker.label.target, tracker.geometry
    assert isinstance(target, Target) and target.image_size == seq.frames[0].shape[:2]
    assert (target.filter_size, target.target_cells, target.cell_size) == (g.filter_size, g.target_cells, g.cell_size)
    assert target.scale == tracker.scale
    # σ of Eq. (1) is the base label's: one cell from its peak it is exp(-1 / 2σ²)
    assert tracker.base_label[1, 0] == pytest.approx(np.exp(-0.5 / target.sigma ** 2), rel=1e-6)
    expected = np.sqrt(np.prod(np.floor(np.asarray(g.target_cells)).clip(1))) * tracker.params.output_sigma_factor
    assert target.sigma == pytest.approx(expected)
    other = seq.ground_truth[0] + [2, 2, 4, 4]  # a new target: new geometry
    tracker.init(seq.frames[0], other)
    assert tracker.label.target.target_cells == tracker.geometry.target_cells != g.target_cells


def test_start_is_checked_like_every_hook():
    class TakesNothing(Label):
        name = "takes_nothing"

        def start(self):  # the tracker passes the target
            pass

        def make(self, g, detection):
            return g, np.zeros((0, 2), int)

    problems = contract_problems(TakesNothing, Label)
    assert problems == ["start(self) cannot be called as start(self, target) (the tracker passes 1 argument)"]
    assert contract_problems(Remembering, Label) == []  # a label without start (0.5 plugins) meets the contract
