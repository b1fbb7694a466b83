"""Hypothesis fuzzing of search specs: spaces, sequence lists and seeds, valid and hostile.

Whatever a spec holds, it loads, or dcfkit's own error names the spec file in its first line; never
another exception. A loaded space samples configs that resolve, and its sequences load each once."""
from __future__ import annotations

import math

import pytest
import yaml
from hypothesis import given
from hypothesis import strategies as st
from test_ablation import write_otb

from dcfkit.autosearch import load_search_spec
from dcfkit.autosearch.study import sample
from dcfkit.errors import DcfkitError

pytest.importorskip("optuna")

SEQUENCES = ("seqA", "seqB", "seqC", "seqD")

# hostile values: wrong types, huge and non-finite numbers, bools for ints, nested garbage
junk = st.one_of(st.none(), st.booleans(), st.integers(-(10**30), 10**30), st.floats(allow_nan=True),
                 st.text(max_size=4), st.lists(st.integers(), max_size=2),
                 st.dictionaries(st.text(max_size=2), st.integers(), max_size=2))
number = st.one_of(st.integers(-3, 60), st.integers(-(2**70), 2**70), st.floats(-100, 100), st.booleans(),
                   st.sampled_from([math.nan, math.inf, -math.inf, 0.0, 1e-300, 1e300]))
bounds = st.one_of(st.lists(number, min_size=2, max_size=2), st.lists(number, max_size=3), junk)
component = st.sampled_from([{"name": "gaussian"}, {"name": "distractor_repressed"}, {"name": "nope"},
                             {"name": "distractor_repressed", "mu": 0.3}, "gaussian", 3])
label = st.one_of(st.integers(0, 2), st.sampled_from(["0", "1", "g", "r", True, "True"]))
choice = st.one_of(st.lists(st.one_of(st.integers(1, 6), st.sampled_from(["a", "1", True, 2.5]), component),
                            max_size=4),
                   st.dictionaries(label, st.one_of(component, st.integers(1, 6)), max_size=4), junk)
when = st.one_of(st.dictionaries(st.sampled_from(["label", "scale", "nope"]), st.one_of(label, junk), max_size=2), junk)
extras = st.fixed_dictionaries({}, optional={"log": st.one_of(st.booleans(), junk), "when": when, "unknown": junk})
entry = st.one_of(st.builds(lambda kind, b, more: {kind: b, **more}, st.sampled_from(["float", "int"]), bounds, extras),
                  st.builds(lambda c, more: {"choice": c, **more}, choice, extras),
                  st.builds(lambda a, b: {"float": a, "int": b}, bounds, bounds), junk)
keys = st.sampled_from(["label", "label.mu", "solver.iterations", "regularizers.temporal.theta",
                        "tracker.output_sigma_factor", "solver", "nope.nothing", ""])
whole = st.one_of(st.integers(-3, 5), st.integers(-(2**70), 2**70), st.booleans(), st.floats(allow_nan=True), junk)
names = st.one_of(st.sampled_from([*SEQUENCES, "seqa", "nope", "", " seqB "]), junk)
HOSTILE = {"sequences": st.one_of(st.lists(names, max_size=12), st.text(alphabet="seqABCD, ", max_size=20), junk),
           "seed": whole, "folds": whole, "trials": whole, "startup_trials": whole,
           "space": st.one_of(st.dictionaries(keys, entry, min_size=1, max_size=4), junk),
           "experiments": st.lists(st.sampled_from(["ope", "tre", "sre", "reset", 1]), max_size=3),
           "baselines": st.dictionaries(st.sampled_from(["KCF", 1, True]), st.sampled_from(["kcf", 2]), max_size=2),
           "dataset": junk, "base": junk, "nonsense": junk}
# a fair space: a choice of labels, mu only under one of them (or, hostile, under both), a whole-number range
fair = st.fixed_dictionaries({
    "label": st.just({"choice": {"g": {"name": "gaussian"}, "r": {"name": "distractor_repressed"}}}),
    "label.mu": st.builds(lambda low, cond: {"float": [low, 1.0], **cond}, st.sampled_from([0.05, 0.2]),
                          st.sampled_from([{"when": {"label": "r"}}, {}])),
    "solver.iterations": st.builds(lambda a, b: {"int": [a, a + b]}, st.integers(1, 3), st.integers(1, 3))})


@st.composite
def spec_dicts(draw):
    """A spec that is mostly fair (so that many load), with a few of its parts hostile."""
    spec = {"dataset": {"name": "otb", "root": "data"}, "base": draw(st.sampled_from(["strcf", "dr2track"])),
            "space": {**draw(fair), **draw(st.dictionaries(keys, entry, max_size=2))}, "folds": 2,
            "sequences": draw(st.lists(st.sampled_from(SEQUENCES), min_size=2, max_size=12))}
    for key in draw(st.lists(st.sampled_from(sorted(HOSTILE)), max_size=2)):
        spec[key] = draw(HOSTILE[key])
    return spec


@pytest.fixture(scope="module")
def folder(tmp_path_factory):
    root = tmp_path_factory.mktemp("search_fuzz")
    for i, name in enumerate(SEQUENCES):
        write_otb(root / "data", name, seed=i, n_frames=2)
    return root


@pytest.mark.filterwarnings("ignore::dcfkit.datasets.DatasetWarning")  # a repeated sequence, as meant
@given(spec=spec_dicts())
def test_fuzzed_search_specs_load_or_name_the_spec(folder, spec):
    path = folder / "spec.yaml"
    path.write_text(yaml.safe_dump(spec, allow_unicode=True), encoding="utf-8")
    try:
        loaded = load_search_spec(path)
    except DcfkitError as exc:  # an unknown dataset's message goes on to list the layouts
        assert str(path) in str(exc).splitlines()[0], str(exc)
        return
    recorded = []
    for number in range(3):  # sampled configs resolve, whatever a range's inside holds
        params = sample(loaded, "all", number, recorded)
        loaded.config(params)
        recorded.append({"params": params, "value": 0.1 * number})
    try:
        found = [s.name for s in loaded.load_sequences()]
    except DcfkitError as exc:
        assert "\n" not in str(exc), str(exc)
        return
    assert len(set(found)) == len(found) and set(found) <= set(SEQUENCES)
