"""The slot table: config resolution checks every spec without building a component, the
Tracker builds each one once, and every reader (config keys, tracker, provenance, the
``components`` listing, docs) follows the one table."""
import pytest

from dcfkit.cli.components import component_rows
from dcfkit.cli.docs import config_reference
from dcfkit.components.base import Component
from dcfkit.config import load_config
from dcfkit.config.slots import KINDS, SLOTS, TOP_LEVEL, build, components, roles
from dcfkit.errors import ConfigError
from dcfkit.registry import get_registry
from dcfkit.tracker import Tracker, load_tracker


@pytest.fixture
def made(monkeypatch):
    """The components constructed while the test runs, by class name."""
    made: list[str] = []
    real = Component.__init__

    def counted(self, params=None):
        made.append(type(self).name)
        real(self, params)
    monkeypatch.setattr(Component, "__init__", counted)
    return made


def test_resolving_a_config_builds_no_component(made):
    config = load_config("dr2track", {"label.mu": 0.3})
    assert made == [] and config["label"]["mu"] == 0.3


def test_the_tracker_builds_each_component_once(made):
    tracker = load_tracker("dr2track")
    # gray, fhog, colornames; the repressed label; box and temporal; the solver, the search, the DSST
    assert sorted(made) == sorted(["gray", "fhog", "colornames", "distractor_repressed", "box", "temporal",
                                   "admm_strcf", "motion_aware", "dsst"])
    assert [f.name for f in tracker.features] == ["gray", "fhog", "colornames"]


@pytest.mark.parametrize("name", ["dr2track", "eco_hc", "csrdcf"])  # between them every slot filled
def test_every_slot_is_a_tracker_attribute_of_its_kind(name):
    config = load_config(name)
    tracker = Tracker(config)
    built = []
    for slot in SLOTS:
        held = getattr(tracker, slot.name)
        assert held is not None or not (slot.required or slot.default), slot  # only an optional slot is empty
        for component in held if slot.many else [held] if held is not None else []:
            assert component.kind == slot.kind, slot
    assert sorted(components(config)) == sorted((c.kind, c.name) for slot in SLOTS
                                                for held in [getattr(tracker, slot.name)]
                                                for c in (held if slot.many else [held] if held is not None else []))


def test_an_absent_role_builds_nothing_and_a_missing_slot_is_named():
    config = load_config("kcf")
    assert config["regularizers"] == {"spatial": None, "temporal": None}
    tracker = Tracker(config)
    assert tracker.spatial is None and tracker.temporal is None
    solver = next(s for s in SLOTS if s.key == "solver")
    with pytest.raises(ConfigError, match=r"kcf: solver: missing"):
        build(solver, get_registry(), {k: v for k, v in config.items() if k != "solver"}, "kcf")


def test_the_readers_follow_the_table():
    assert TOP_LEVEL[4:] == tuple(dict.fromkeys(s.top for s in SLOTS))
    assert KINDS == tuple(dict.fromkeys(s.kind for s in SLOTS))
    assert roles("regularizers") == ("spatial", "temporal")
    assert {row["kind"] for row in component_rows(get_registry())} == set(KINDS)
    reference = config_reference()
    for slot in SLOTS:
        assert f"| `{slot.top}` |" in reference
        if slot.default is not None:
            assert f"| `{slot.key}` | `{slot.default}` |" in reference
    resolved = load_config({"features": ["gray"], "label": "gaussian", "solver": "ridge"})
    # then each slot's key in table order; an optional slot left empty (memory, schedule, mask,
    # channel_weights) has none, as before it existed
    kept = dict.fromkeys(s.top for s in SLOTS if s.required or s.default or s.role)
    assert list(resolved) == ["name", "tracker", *kept] and "memory" not in kept and "mask" not in kept
    masked = load_config({"features": ["gray"], "label": "gaussian", "solver": "admm_csr", "mask": "csr_segmentation",
                          "channel_weights": "csr_reliability"})
    assert list(masked) == ["name", "tracker", *kept, "mask", "channel_weights"]
    assert {s.key: resolved[s.key]["name"] for s in SLOTS if s.default} == {"search": "fixed", "scale": "pyramid"}
