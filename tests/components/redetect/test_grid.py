"""The grid re-detector: its candidate regions, their order over a lost stretch, and acceptance."""
import numpy as np
import pytest

from dcfkit.components.redetect import Grid, grid_offsets
from dcfkit.contracts import ContractViolation
from dcfkit.registry import Registry, get_registry


def test_grid_offsets_ring_by_ring_clockwise():
    offsets = grid_offsets(1)
    assert offsets.tolist() == [[0, 0], [-1, -1], [-1, 0], [-1, 1], [0, 1], [1, 1], [1, 0], [1, -1], [0, -1]]
    two = grid_offsets(2)
    assert len(two) == 25 and len({tuple(o) for o in two}) == 25
    assert np.abs(two[9:]).max(axis=1).min() == 2  # the second ring after the first


def test_candidates_sweep_around_the_last_reliable_centre_a_few_a_frame():
    g = Grid(Grid.Params(stride=0.5, rings=1, per_frame=3))
    g.observe(np.array([100.0, 100.0]), reliable=True)
    g.observe(np.array([150.0, 40.0]), reliable=False)  # drifted: the anchor stays at the reliable centre
    size, image = np.array([40.0, 80.0]), (400, 400)
    # searched this frame at the anchor: ring 0 is left out; spacing (20, 40)
    first = g.candidates(np.array([100.0, 100.0]), size, image)
    assert first.tolist() == [[80, 60], [80, 100], [80, 140]]
    second = g.candidates(np.array([100.0, 100.0]), size, image)
    assert second.tolist() == [[100, 140], [120, 140], [120, 100]]
    third = g.candidates(np.array([100.0, 100.0]), size, image)
    assert third.tolist() == [[120, 60], [100, 60], [80, 60]]  # wraps around to the start
    g.observe(np.array([100.0, 100.0]), reliable=True)  # found again: the next loss starts at the nearest
    assert g.candidates(np.array([300.0, 300.0]), size, image)[0].tolist() == [100, 100]


def test_candidates_stay_on_the_image_and_whole_frame_covers_it():
    g = Grid(Grid.Params(stride=1.0, rings=1, per_frame=100))
    g.observe(np.array([5.0, 5.0]), reliable=True)
    near = g.candidates(np.array([5.0, 5.0]), np.array([10.0, 10.0]), (50, 50))
    assert near.tolist() == [[5, 15], [15, 15], [15, 5]]  # the rest lie off the image
    whole = Grid(Grid.Params(stride=1.0, whole_frame=True, per_frame=1000))
    whole.observe(np.array([5.0, 5.0]), reliable=True)
    points = whole.candidates(np.array([5.0, 5.0]), np.array([10.0, 10.0]), (50, 50))
    assert len(points) == 24 and points.max() == 45  # every grid point of the 50 x 50 frame but the searched one


def test_accept_needs_a_reliable_score_and_the_margin():
    g = Grid(Grid.Params(margin=2.0))
    assert g.accept(0.3, np.array([0.9, 0.5])) == -1  # none reliable
    assert g.accept(0.3, np.array([0.9, 1.1])) == 1
    assert g.accept(0.8, np.array([1.5, 1.1])) == -1  # reliable, but not twice the frame's own 0.8
    assert g.accept(0.8, np.array([1.7, 1.1])) == 0
    assert g.accept(0.1, np.zeros(0)) == -1


def test_grid_is_registered():
    assert "grid" in get_registry().names("redetect")


class _Overreaching(Grid):
    name = "overreaching"

    def accept(self, current, scores):
        return len(scores)


def test_an_accepted_index_beyond_the_candidates_is_a_contract_violation():
    registry = Registry()
    registry.register(_Overreaching)
    built = registry.build("redetect", {"name": "overreaching"}, "test.yaml: redetect")
    with pytest.raises(ContractViolation, match="expected -1 or the index of one of the 2 candidates"):
        built.accept(0.5, np.array([1.0, 2.0]))
