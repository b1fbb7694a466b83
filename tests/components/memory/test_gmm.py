"""ECO's sample space model on hand-computed cases: one-number samples, whose distances are
2 (a - b)² (every half-spectrum coefficient counts twice)."""
import numpy as np
import pytest

from dcfkit.components.memory import GaussianMixture, RunningAverage
from dcfkit.registry import get_registry


def memory(capacity, rate):
    m = GaussianMixture(GaussianMixture.Params(capacity=capacity, learning_rate=rate))
    m.reset()
    return m


def values(m):
    return m.samples[0][:, 0].real


def put(m, v):
    m.insert([np.array([v], np.complex64)])


def test_slots_fill_with_decaying_weights():
    m = memory(3, 0.1)
    for v in (0.0, 10.0, 20.0):
        put(m, v)
    assert m.count == 3 and list(values(m)) == [0, 10, 20]
    assert m.weights == pytest.approx([0.81, 0.09, 0.1])
    assert m.distance[0, 1] == pytest.approx(200) and m.distance[1, 2] == pytest.approx(200)
    assert m.distance[0, 2] == pytest.approx(800) and np.isinf(np.diag(m.distance)).all()


def test_a_new_sample_merges_into_its_nearest_component():
    m = memory(3, 0.1)
    for v in (0.0, 10.0, 20.0, 11.0):
        put(m, v)
    # 11 is 2·1² from 10, closer than any kept pair (200): weights x 0.9, then 10 and 11 averaged
    w1 = 0.09 * 0.9
    merged = (w1 * 10 + 0.1 * 11) / (w1 + 0.1)
    assert values(m) == pytest.approx([0, merged, 20], rel=1e-6)
    assert m.weights == pytest.approx([0.729, w1 + 0.1, 0.09])
    assert m.distance[0, 1] == pytest.approx(2 * merged**2, rel=1e-5)
    assert m.distance[1, 2] == pytest.approx(2 * (20 - merged) ** 2, rel=1e-5)


def test_the_closest_pair_merges_and_the_new_sample_takes_the_lighter_slot():
    m = memory(3, 0.1)
    for v in (0.0, 10.0, 20.0, 11.0, 100.0):
        put(m, v)
    # 100 is 2·80² from 20; the closest kept pair is (10.55, 20): merged into the heavier slot 1
    a = (0.081 * 10 + 0.1 * 11) / 0.181
    w = np.array([0.729, 0.181, 0.09]) * 0.9
    merged = (w[1] * a + w[2] * 20) / (w[1] + w[2])
    assert values(m) == pytest.approx([0, merged, 100], rel=1e-6)
    assert m.weights == pytest.approx([w[0], w[1] + w[2], 0.1])
    assert m.weights.sum() == pytest.approx(1)
    assert m.distance[1, 2] == pytest.approx(2 * (100 - merged) ** 2, rel=1e-5)


def test_a_component_lighter_than_the_floor_is_replaced():
    m = memory(2, 0.9)  # floor 0.9 · 0.1⁴ = 9e-5
    for v in (0.0, 10.0, 10.0, 10.0, 10.0, 10.0):  # each 10 merges into slot 1: slot 0 decays x 0.1
        put(m, v)
    assert m.weights[0] == pytest.approx(1e-5, rel=1e-3)
    put(m, 50.0)
    assert list(values(m)) == [50, 10]
    assert m.weights == pytest.approx([0.9, 0.1], rel=1e-4)
    assert m.distance[0, 1] == pytest.approx(2 * 40**2)


def test_replace_recomputes_the_slots_distances():
    m = memory(3, 0.1)
    for v in (0.0, 10.0):
        put(m, v)
    m.replace(0, [np.array([4.0], np.complex64)])
    assert values(m)[0] == 4 and m.distance[0, 1] == pytest.approx(72)


def test_running_average_keeps_one_slot():
    m = RunningAverage(RunningAverage.Params(learning_rate=0.25))
    m.reset()
    m.insert([np.array([4.0])])
    m.insert([np.array([8.0])])
    assert m.count == 1 and m.weights[0] == 1 and m.samples[0][0, 0] == 5.0


def test_memories_are_registered_as_their_kind():
    registry = get_registry()
    assert {"gmm", "running_average"} <= set(registry.names("memory"))
