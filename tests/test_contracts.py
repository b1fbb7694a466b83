"""The return-value contracts of component hooks (dcfkit.contracts): a plugin component that
returns garbage stops the run on that frame with an error naming the component, its
provider and the hook, instead of writing garbage boxes."""
from __future__ import annotations

import re

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp
from test_base import TINY, tiny_sequence

import dcfkit
from dcfkit import registry as reg
from dcfkit.components.features.gray import Gray
from dcfkit.components.labels.gaussian import Gaussian
from dcfkit.components.regularizers import BoxWindow
from dcfkit.components.scale.pyramid import Pyramid
from dcfkit.components.search.strategies import MotionAware
from dcfkit.components.solvers import ADMMStrcf
from dcfkit.contracts import ContractViolation, array, pair, scalar, within_grid
from dcfkit.experiments.loop import TrackerFailure, track

PROVIDER = "evil-plugin"


def plugin(base: type, kind: str, hook: str, returned) -> dict:
    """Register, as plugin ``evil-plugin`` would, a ``base`` subclass named ``evil_<kind>`` whose
    ``hook`` returns ``returned(args, self)``; return the overrides that put it into TINY."""
    original = getattr(base, hook)

    def replaced(self, *args):
        original(self, *args)  # keeps the component's state as the tracker expects it
        return returned(args, self)

    cls = type(f"Evil{base.__name__}", (base,), {"name": f"evil_{kind}", hook: replaced})
    registry = reg.get_registry()
    registry._provider = PROVIDER  # as _run_plugin sets it while the plugin registers
    try:
        registry.register(cls)
    finally:
        registry._provider = "?"
    spec = {"name": cls.name}
    return {"features": [spec]} if kind == "feature" else (
        {f"regularizers.{cls.role}": spec} if kind == "regularizer" else {kind: spec})


@pytest.fixture(autouse=True)
def own_registry(monkeypatch):
    monkeypatch.setattr(reg, "_REGISTRY", reg.build_registry(external=False))


def tracked(overrides: dict) -> np.ndarray:
    """The boxes of TINY with ``overrides`` on the tiny sequence."""
    seq = tiny_sequence()
    return track(dcfkit.load_tracker(TINY, overrides=overrides), seq.frames, seq.ground_truth[0]).boxes


SHAPE = r"shape \(.*\), expected \(.*\)"
CASES = [  # (base, kind, hook, returned(args, component), the error after "<hook>() ")
    (Pyramid, "scale", "update", lambda a, c: -1.0, r"returned -1\.0, expected \(0, inf\]"),
    (Pyramid, "scale", "update", lambda a, c: 0, r"returned 0\.0, expected \(0, inf\]"),
    (Pyramid, "scale", "update", lambda a, c: [1, 2], r"returned \[1, 2\], expected a real number in \(0, inf\]"),
    (Pyramid, "scale", "update", lambda a, c: float("nan"), r"returned nan, expected \(0, inf\]"),
    (Pyramid, "scale", "search_factors", lambda a, c: np.array([1.0, -0.5]), r"returned array\(\[ 1\. , -0\.5\]\), "
                                                                              r"expected one or more numbers in "
                                                                              r"\[0\.1, 10\]"),
    (Pyramid, "scale", "search_factors", lambda a, c: np.array([2386.0]), r"returned array\(\[2386\.\]\), expected one "
                                                                          r"or more numbers in"),
    (Pyramid, "scale", "search_factors", lambda a, c: np.ones((2, 2)), "returned " + SHAPE),
    (Gaussian, "label", "make", lambda a, c: (a[0].astype(np.complex64), np.zeros((0, 2), int)),
     r"returned y of dtype complex64, expected real floats"),
    (Gaussian, "label", "make", lambda a, c: (a[0] * np.nan, np.zeros((0, 2), int)), r"returned y: NaN or infinite"),
    (Gaussian, "label", "make", lambda a, c: (a[0], np.array([[np.nan, 1.0]])), "returned offsets of dtype float64, "
                                                                               "expected integers"),
    (Gaussian, "label", "make", lambda a, c: (a[0], np.array([[10**6, 0]])), r"returned offsets: offsets beyond"),
    (ADMMStrcf, "solver", "response", lambda a, c: np.zeros((len(a[1]), *a[2]), np.complex64),
     r"returned dtype complex64, expected real floats"),
    (ADMMStrcf, "solver", "train", lambda a, c: a[0] * np.nan, "returned NaN or infinite values"),
    (BoxWindow, "regularizer", "weights_squared", lambda a, c: np.ones(7, np.float32), "returned " + SHAPE),
    (BoxWindow, "regularizer", "weights_squared", lambda a, c: np.full(a[0], np.nan, np.float32),
     "returned NaN values"),
    (BoxWindow, "regularizer", "weights_squared", lambda a, c: -np.ones(a[0], np.float32), "returned negative values"),
    (MotionAware, "search", "centre", lambda a, c: np.array([np.nan, 1.0]), "returned NaN or infinite values"),
    (Gray, "feature", "extract", lambda a, c: np.zeros((1, 8, 8), np.complex64), "returned dtype complex64"),
    (Gray, "feature", "channels", lambda a, c: 0, r"returned 0\.0, expected \[1, inf\]"),
    (Gray, "feature", "extract", lambda a, c: np.full((1, a[0].shape[0] // a[1], a[0].shape[1] // a[1]), 3e38,
                                                      np.float32), r"returned values as large as 3e\+38"),
    (Pyramid, "scale", "search_factors", lambda a, c: np.ma.array([1.0, np.nan], mask=[0, 1]),
     "returned a MaskedArray, expected a numpy array"),
    (MotionAware, "search", "centre", lambda a, c: np.ma.array([1.0, 2.0]), "returned a MaskedArray"),
    (MotionAware, "search", "centre", lambda a, c: np.array([1e300, 1e300]), r"returned values as large as 1e\+300"),
    (Gaussian, "label", "make", lambda a, c: (a[0], np.array([[-2**63, -2**63]], np.int64)),  # abs() of it is < 0
     r"returned offsets: offsets beyond"),
]


@pytest.mark.parametrize("base, kind, hook, returned, said", CASES, ids=[f"{c[2]}-{i}" for i, c in enumerate(CASES)])
def test_a_hook_that_breaks_its_contract_is_named_with_its_provider(base, kind, hook, returned, said):
    overrides = plugin(base, kind, hook, returned)
    with pytest.raises((TrackerFailure, ContractViolation)) as caught:
        tracked(overrides)
    # channels and search_factors: at load too, where the sample budget is checked
    assert caught.type is TrackerFailure or hook in ("channels", "search_factors"), caught.value
    message = str(caught.value)
    assert re.search(rf"{kind} 'evil_{kind}' \(from {PROVIDER}\): {re.escape(hook)}\(\) {said}", message), message


def test_a_scale_is_held_to_the_limits_given_to_init_whatever_the_estimator_keeps():
    class Forgetful(Pyramid):  # keeps no limits of its own
        name = "forgetful"

        def init(self, image, centre, base_target, scale, limits):
            self.base_target = base_target

        def update(self, image, centre, scale):
            return 1e-300

    registry = reg.get_registry()
    registry._provider = PROVIDER
    try:
        registry.register(Forgetful)
    finally:
        registry._provider = "?"
    with pytest.raises(TrackerFailure, match=r"scale 'forgetful' \(from evil-plugin\): update\(\) returned 1e-300, "
                                             r"outside the limits \[[\d.e+-]+, [\d.e+-]+\] given to init"):
        tracked({"scale": {"name": "forgetful"}})


def growing(args, estimator):
    """One factor on the first call (what the sample budget is checked for), then more."""
    calls = estimator.__dict__.setdefault("calls", [])
    calls.append(0)
    return np.ones(len(calls))


def test_more_search_factors_than_budgeted_are_refused():
    with pytest.raises(TrackerFailure, match=r"scale 'evil_scale' \(from evil-plugin\): search_factors\(\) returned "
                                             r"\d+ factors, more than the 1 of its first call"):
        tracked(plugin(Pyramid, "scale", "search_factors", growing))


def test_a_scale_the_estimator_changes_after_returning_it_changes_nothing():
    def update(args, estimator):
        estimator.given = np.array(float(args[2]))  # a 0-d array, which it changes on its next call
        return estimator.given

    def factors(args, estimator):
        if hasattr(estimator, "given"):
            estimator.given[()] = -1.0
        return np.ones(1)

    overrides = plugin(Pyramid, "scale", "update", update)
    cls = reg.get_registry().entry("scale", "evil_scale").cls
    cls.search_factors = lambda self: factors((), self)
    boxes = tracked(overrides)
    assert np.isfinite(boxes).all() and (boxes[:, 2:] > 0).all()


def test_a_solver_that_writes_into_w2_is_named_not_the_regularizer():
    def train(args, solver):
        args[2][0, 0] = np.nan  # w2
        return args[0]

    with pytest.raises(TrackerFailure, match=r"solver 'evil_solver' \(from evil-plugin\): train\(\) raised "
                                             r"ValueError: assignment destination is read-only"):
        tracked(plugin(ADMMStrcf, "solver", "train", train))


def test_a_hook_that_raises_is_named_with_its_provider():
    def boom(args, component):
        raise ZeroDivisionError("oops")

    with pytest.raises(TrackerFailure, match=r"^frame 2: update raised ContractViolation: scale "
                                             r"'evil_scale' \(from evil-plugin\): update\(\) raised "
                                             r"ZeroDivisionError: oops \(at .*test_contracts.py:\d+\)$"):
        tracked(plugin(Pyramid, "scale", "update", boom))


def test_the_builtins_keep_their_contracts_on_every_shipped_config():
    seq = tiny_sequence()
    for name in ("kcf", "dsst", "strcf", "bacf", "dr2track"):
        boxes = track(dcfkit.load_tracker(name), seq.frames, seq.ground_truth[0]).boxes
        assert np.isfinite(boxes).all() and (boxes[:, 2:] > 0).all()


@pytest.mark.parametrize("check, value, args, problem", [
    (scalar(0, 1), True, (), "True, expected a real number in [0, 1]"),
    (scalar(0, 1, inf=True), np.inf, (), None),
    (scalar(0, 1), np.float32(0.5), (), None),
    (scalar(0, 1), np.array(0.5), (), None),
    (scalar(1, 9, integer=True), 2.0, (), "2.0, expected an integer in [1, 9]"),
    (array((2,)), [1.0, 2.0], (), "a list, expected a numpy array of real floats"),
    (array((None, 2), kinds="iu"), np.zeros((3, 2), int), (), None),
    (array(lambda a, c: a[0]), np.zeros((2, 3)), ((2, 4),), "shape (2, 3), expected (2, 4)"),
    (array(finite=False, nonnegative=True), np.array([np.inf, 0.0]), (), None),
    (pair(array(), array(), ("a", "b")), (np.zeros(1),), (), "a tuple, expected a tuple (a, b)"),
    (within_grid, np.array([[2, -3]]), (np.zeros((3, 3)),), "offsets beyond the 3x3 grid (max |dy|, |dx| = 2, 3)"),
    (within_grid, np.zeros((0,)), (np.zeros((3, 3)),), None),
])
def test_checks_by_hand(check, value, args, problem):
    assert check(value, args, None) == problem


def returned_values() -> st.SearchStrategy:
    """Anything a hook might return: arrays of any dtype kind and small shape (NaN, inf and
    extremes among their values), scalars, lists, tuples, None."""
    arrays = hnp.arrays(st.sampled_from([np.float32, np.float64, np.int64, np.complex64, np.bool_]),
                        hnp.array_shapes(min_dims=0, max_dims=3, max_side=6))
    scalars = st.one_of(st.floats(), st.integers(-10**6, 10**6), st.booleans(), st.none())
    return st.one_of(arrays, scalars, st.lists(scalars, max_size=3), st.tuples(arrays, arrays))


FUZZED = [(Pyramid, "scale", "update"), (Pyramid, "scale", "search_factors"), (Gaussian, "label", "make"),
          (BoxWindow, "regularizer", "weights_squared"), (MotionAware, "search", "centre")]


@pytest.mark.parametrize("base, kind, hook", FUZZED, ids=[f[2] for f in FUZZED])
@settings(max_examples=40, deadline=None)
@given(value=returned_values())
def test_whatever_a_hook_returns_ends_in_good_boxes_or_the_named_hook(base, kind, hook, value, monkeypatch):
    monkeypatch.setattr(reg, "_REGISTRY", reg.build_registry(external=False))
    try:
        boxes = tracked(plugin(base, kind, hook, lambda a, c: value))
    except (TrackerFailure, ContractViolation) as exc:  # ContractViolation: at load, search_factors' budget
        assert f"{kind} 'evil_{kind}' (from {PROVIDER}): {hook}() " in str(exc), str(exc)
        return
    assert np.isfinite(boxes).all() and (boxes[:, 2:] > 0).all(), boxes


def test_a_component_whose_hooks_cannot_be_wrapped_is_refused_by_name():
    class Slotted(Pyramid):
        __slots__ = ()
        name = "slotted"

    class NoDict:  # what __slots__ all the way down gives: no instance attributes
        __slots__ = ("params",)
        kind, name = "scale", "slotted"

        def update(self, image, centre, scale):
            return scale

    from dcfkit.contracts import Hook, checked
    from dcfkit.errors import RegistryError

    with pytest.raises(RegistryError, match=r"scale 'slotted' \(from p\): dcfkit cannot check its update\(\)"):
        checked(NoDict(), "p", {"update": None})
    assert isinstance(checked(Slotted(), "p", {"update": None}).update, Hook)  # a base with a __dict__: wrapped


async def _async_start(self, target):
    self.started = True


async def _async_generator_start(self, target):
    yield target


def _generator_start(self, target):
    self.started = True
    yield


def _generator_make(self, g, detection):
    yield g


@pytest.mark.parametrize("hook, body, said", [
    ("start", _generator_start, "a generator function (it yields): the tracker's call would return a generator and "
                                "run none of it"),
    ("start", _async_start, "an async function: the tracker's call would return a coroutine"),
    ("start", _async_generator_start, "an async generator function"),
    ("make", _generator_make, "a generator function"),  # a kind's own hook too
])
def test_a_hook_that_would_not_run_when_called_is_refused_at_registration(hook, body, said):
    from dcfkit.errors import RegistryError

    registry = reg.build_registry(external=False)
    registry._provider = PROVIDER
    with pytest.raises(RegistryError, match=re.escape(f"label 'lazy' (from {PROVIDER}): {hook}() is {said}")):
        registry.register(type("Lazy", (Gaussian,), {"name": "lazy", hook: body}))
    registry.register(type("Eager", (Gaussian,), {"name": "eager", "start": lambda self, target: None}))
