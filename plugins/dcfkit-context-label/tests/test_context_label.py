"""The context_aware label against hand-computed labels on small grids."""
import numpy as np
import pytest

from dcfkit.components.labels import Detection, gaussian_label
from dcfkit.errors import ConfigError
from dcfkit.registry import Registry
from dcfkit_context_label import dcfkit_register_components
from dcfkit_context_label.label import ContextAware


def test_fixed_context_patches_are_repressed():
    # a 12x16 label, target 2x3 cells: the context patches sit 2 rows up/down and 3 columns left/right
    g = gaussian_label((12, 16), 1.0)
    det = Detection(np.zeros((12, 16), np.float32), peak=(5, 7), target_cells=(2.0, 3.0))
    y, offsets = ContextAware().make(g, det)
    assert offsets.tolist() == [[-2, 0], [2, 0], [0, -3], [0, 3]]
    expected = g.copy()
    for row, col in [(10, 0), (2, 0), (0, 13), (0, 3)]:  # -2 % 12 = 10, -3 % 16 = 13
        expected[row, col] = g[row, col] - 0.1
    np.testing.assert_allclose(y, expected, atol=1e-7)
    assert y.dtype == np.float32 and y[0, 0] == 1.0


def test_diagonals_and_distance():
    g = gaussian_label((12, 16), 1.0)
    det = Detection(np.zeros((12, 16), np.float32), peak=(0, 0), target_cells=(2.0, 2.0))
    label = ContextAware(ContextAware.Params(strength=0.5, distance=1.5, diagonals=True))
    y, offsets = label.make(g, det)
    assert offsets.tolist() == [[-3, 0], [3, 0], [0, -3], [0, 3], [-3, -3], [-3, 3], [3, -3], [3, 3]]
    assert y[9, 13] == pytest.approx(g[9, 13] - 0.5) and y[3, 3] == pytest.approx(g[3, 3] - 0.5)
    assert np.count_nonzero(y != g) == 8


def test_repression_scaled_by_the_last_response():
    # response peak 2.0 at (5, 7); 1.0 below the target (offset (2, 0)), -1.0 above it, nothing left or right
    r = np.zeros((12, 16), np.float32)
    r[5, 7], r[7, 7], r[3, 7] = 2.0, 1.0, -1.0
    g = gaussian_label((12, 16), 1.0)
    label = ContextAware(ContextAware.Params(strength=0.2, use_response=True))
    y, offsets = label.make(g, Detection(r, (5, 7), (2.0, 3.0)))
    assert offsets.tolist() == [[2, 0]]  # a negative or zero response is not repressed further
    expected = g.copy()
    expected[2, 0] -= 0.2 * 1.0 / 2.0
    np.testing.assert_allclose(y, expected, atol=1e-7)


def test_patches_outside_the_sample_or_on_the_target_are_skipped():
    g = gaussian_label((8, 8), 1.0)
    det = Detection(np.zeros((8, 8), np.float32), (0, 0), target_cells=(0.4, 5.0))
    y, offsets = ContextAware().make(g, det)  # dy rounds to 0 (on the target), |dx| = 5 > 3 (outside)
    assert offsets.shape == (0, 2) and np.array_equal(y, g)


def test_first_frame_and_flat_response_give_the_gaussian():
    g = gaussian_label((8, 8), 1.0)
    assert np.array_equal(ContextAware().make(g, None)[0], g)
    flat = Detection(np.zeros((8, 8), np.float32), (0, 0), (2.0, 2.0))
    label = ContextAware(ContextAware.Params(use_response=True))
    assert np.array_equal(label.make(g, flat)[0], g)


def test_the_hook_registers_the_label_and_parameters_are_checked():
    registry = Registry()
    dcfkit_register_components(registry)
    assert registry.names("label") == ["context_aware"]
    label = registry.build("label", {"name": "context_aware", "strength": 0.3}, "test.yaml: label")
    assert label.params == ContextAware.Params(strength=0.3)
    with pytest.raises(ConfigError, match="test.yaml: label .* strength must be >= 0"):
        registry.build("label", {"name": "context_aware", "strength": -1}, "test.yaml: label")
    with pytest.raises(ConfigError, match=r"unknown parameter 'distanse' \(did you mean 'distance'\?\)"):
        registry.build("label", {"name": "context_aware", "distanse": 2}, "test.yaml: label")
