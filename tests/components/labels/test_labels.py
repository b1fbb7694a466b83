"""Label generators: Eq. (1)'s Gaussian and Eq. (3)'s distractor repression."""
import numpy as np
import pytest

import dcfkit
from dcfkit.components.labels.base import Detection, Label, gaussian_label
from dcfkit.components.labels.distractors import DistractorRepressed
from dcfkit.components.labels.gaussian import Gaussian
from dcfkit.datasets.synthetic import make_sequence
from dcfkit.errors import ConfigError
from dcfkit.numerics.response import local_maxima
from dcfkit.params import parse_params


def test_gaussian_label_peaks_at_origin_and_is_symmetric():
    g = gaussian_label((10, 9), sigma=1.5)
    assert g[0, 0] == pytest.approx(1.0)
    assert g.argmax() == 0
    assert g[1, 0] == pytest.approx(np.exp(-0.5 / 1.5**2))
    assert g[1, 0] == pytest.approx(g[-1, 0]) and g[0, 2] == pytest.approx(g[0, -2])


def response_with_peaks(shape, peaks):
    r = np.zeros(shape, np.float32)
    for (y, x), v in peaks.items():
        r[y, x] = v
    return r


def test_repressed_label_hand_computed_subtractive():
    # target peak at (10, 12) of a 20x24 map, distractors at offsets (+6, 0), (0, -8), one inside the target area
    r = response_with_peaks((20, 24), {(10, 12): 2.0, (16, 12): 1.0, (10, 4): 0.5, (11, 13): 1.5})
    det = Detection(r, (10, 12), target_cells=(4.0, 4.0))
    g = gaussian_label((20, 24), 2.0)
    label = DistractorRepressed(DistractorRepressed.Params(top_n=30, mu=0.25, variant="subtractive"))
    y, offsets = label.make(g, det)
    assert sorted(map(tuple, offsets.tolist())) == [(0, -8), (6, 0)]
    expected = g.copy()
    expected[6, 0] -= 0.25 * 1.0 / 2.0       # the [η] shift puts the offset (6, 0) at label index (6, 0)
    expected[0, -8] -= 0.25 * 0.5 / 2.0
    np.testing.assert_allclose(y, expected, atol=1e-7)


def test_repressed_label_multiplicative_and_top_n():
    r = response_with_peaks((20, 20), {(0, 0): 1.0, (7, 0): 0.9, (0, 7): 0.6, (-7 % 20, -7 % 20): 0.3})
    det = Detection(r, (0, 0), target_cells=(3.0, 3.0))
    g = gaussian_label((20, 20), 4.0)
    label = DistractorRepressed(DistractorRepressed.Params(top_n=2, mu=0.5, variant="multiplicative"))
    y, offsets = label.make(g, det)
    assert offsets.tolist() == [[7, 0], [0, 7]]  # the two strongest, strongest first
    expected = g.copy()
    expected[7, 0] *= 1 - 0.5 * 0.9
    expected[0, 7] *= 1 - 0.5 * 0.6
    np.testing.assert_allclose(y, expected, atol=1e-7)


def test_without_detection_or_with_flat_response_the_label_is_the_gaussian():
    g = gaussian_label((8, 8), 1.0)
    label = DistractorRepressed()
    assert np.array_equal(label.make(g, None)[0], g)
    flat = Detection(np.zeros((8, 8), np.float32), (0, 0), (2.0, 2.0))
    assert np.array_equal(label.make(g, flat)[0], g)
    assert np.array_equal(Gaussian().make(g, flat)[0], g)


def test_exclusion_zone_and_wrapped_offsets_of_the_distractors():
    """P^T of Eq. (3) keeps maxima more than half a target size from the peak, measuring circular
    offsets: a peak near the map's edge has its neighbours across the edge."""
    r = np.zeros((20, 20), np.float32)
    r[18, 1] = 1.0  # the target's peak; target 4x6 cells: excluded if |dy| <= 2 and |dx| <= 3
    r[0, 1] = 0.9   # dy = +2 across the edge: inside the zone
    r[18, 4] = 0.8  # dx = +3: inside
    r[18, 17] = 0.6  # dx = -4 across the edge: a distractor
    r[15, 1] = 0.5  # dy = -3: a distractor
    r[5, 10] = 0.3  # dy = -13 = +7 circularly, dx = +9
    det = Detection(r, (18, 1), (4.0, 6.0))
    offsets, values = DistractorRepressed().distractors(det)
    assert offsets.tolist() == [[0, -4], [-3, 0], [7, 9]]
    np.testing.assert_allclose(values, [0.6, 0.5, 0.3])


@pytest.mark.parametrize("values, message", [
    ({"mu": 1e300}, r"label: mu must be in \[0, 1e\+06\], got 1e\+300"),                        # y = g - μR̃ was -inf in float32
    ({"neighbourhood": 10**6 + 1}, r"label: neighbourhood must be in \[3, 101\], got 1000001"),  # a wrap-padded 10^6-wide copy
])
def test_repression_values_beyond_float32_or_memory_are_refused(values, message):
    with pytest.raises(ConfigError, match=message):
        parse_params(DistractorRepressed.Params, values, "label")


def test_the_widest_neighbourhood_works_on_a_map_smaller_than_it():
    """101 cells on an 8x8 circular map: every cell is in every other's neighbourhood, so the one
    maximum is the map's."""
    r = np.zeros((8, 8), np.float32)
    r[2, 3], r[6, 6] = 1.0, 0.5
    rows, cols = local_maxima(r, 101)
    assert (rows.tolist(), cols.tolist()) == ([2], [3])


def test_init_resets_the_label_before_the_first_frame_of_a_target():
    """The tracker calls reset() on every init: a label keeping per-target state starts afresh."""
    calls = []

    class Recording(Label):
        name = "recording"

        def reset(self):
            calls.append("reset")

        def make(self, g, detection):
            calls.append("first" if detection is None else "later")
            return g, np.zeros((0, 2), int)

    seq = make_sequence(n_frames=3, seed=2)
    tracker = dcfkit.load_tracker("strcf", overrides={"scale.n_scales": 1})
    tracker.label = Recording()
    for _ in range(2):
        tracker.init(seq.frames[0], seq.ground_truth[0])
        tracker.update(seq.frames[1])
    assert calls == ["reset", "first", "later"] * 2
